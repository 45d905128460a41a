// FBP's readings of +inf where the object stopped the beam (metal), told apart from dead
// elements as training tells them (model/starved_readings.hpp), one detector row at a time: a
// row reads the same in any slab of a stack, so a slab's FBP does not depend on the cut.
#pragma once

#include <cstddef>

#include "riner/array.hpp"
#include "riner/geometry.hpp"

namespace riner::analytic {

struct StoppedBeamRows {
  std::size_t count = 0;    // readings of +inf kept as a stopped beam
  float largest_floor = 0;  // the largest row floor they were set to (0: none set)
};

// `readings` [views, elements] or [views, rows, elements] under `g` (its rows: readings' own).
// Each row's corrupt spikes and +inf that are no stopped beam become NaN; with `at_floor` the
// stopped beam's readings beside a reading near the row's floor (a metal's edge) become the
// floor (model/starved_readings.hpp's, of the row alone), the others NaN; else they stay +inf.
StoppedBeamRows stopped_beam_rows(Array& readings, const Geometry& g, bool at_floor);

}  // namespace riner::analytic
