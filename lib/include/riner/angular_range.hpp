// Whether a parallel-beam scan's views turn as far as its geometry says. A common mistake is a
// 360-degree scan given 180 degrees of angles (or the reverse): the reconstruction is garbage
// and the centre finders, which pair views half a turn apart, return a confident wrong axis.
// The readings tell: a view and the view half a turn later are mirror images about the axis,
// a view and the view a full turn later are the same. Under the geometry's angles of a
// half-turn, the last view is the first's mirror image and views a quarter-turn apart are
// unrelated; had the scan turned twice as far, the last view would be the first as it is, and
// views a quarter-turn apart (by the geometry) would be mirror images. A full turn's reading
// is the same with the roles swapped. Each comparison is relative to the spread of the
// readings compared (noise against noise about 1), after each element's stripe (its mean over
// the views less the running median of its neighbours' means) is taken out, since a stripe
// cancels between a view and itself but not between mirror images.
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "riner/scan.hpp"

namespace riner {

enum class TurnReading {
  kNotChecked,  // not a parallel beam, or the angles span neither a half nor a full turn
  kUndecided,   // the comparisons say neither clearly (a symmetric object, noise, strong rings)
  kHalfTurn,
  kFullTurn,
};

struct AngularRangeEvidence {
  TurnReading geometry = TurnReading::kNotChecked;  // what the angles say
  TurnReading readings = TurnReading::kNotChecked;  // what the views say
  double span_deg = 0.0;                            // the angles' span
  // The end pairs (views the geometry's span apart: the first and the last) and the middle
  // pairs (half the span apart), each pair's readings compared as they are and mirrored about
  // the best axis: the mean squared difference relative to their spread.
  std::size_t end_pairs = 0, middle_pairs = 0;
  double end_same = 0.0, end_mirrored = 0.0;
  double middle_same = 0.0, middle_mirrored = 0.0;
};

// Reads the views of a 2D or 3D parallel-beam scan (3D: four rows spread over the detector).
// kNotChecked for a divergent beam, fewer than 8 views or 16 detector columns, or angles that
// span neither a half-turn nor a full turn (within 4 angular steps).
AngularRangeEvidence read_angular_range(const Scan& scan);

// One line where the views say a half-turn and the angles a full turn, or the reverse; nullopt
// where they agree or either is undecided.
std::optional<std::string> angular_range_doubt(const AngularRangeEvidence& evidence);
std::optional<std::string> angular_range_doubt(const Scan& scan);

}  // namespace riner
