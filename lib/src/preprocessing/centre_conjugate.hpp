// The rotation axis of a full-turn fan-beam scan from conjugate rays: a ray leaves the source
// circle where the source of a view about half a turn later sits, and that view's ray back
// through the same line reads the same line integral. Both rays are computed with the
// geometry's detector offset, so they meet only when that offset is the scan's: the offset is
// where the mean squared difference of every ray and its conjugate (read between the two
// nearest views, each through the line's point nearest the axis) is least: every 2 px on a
// sixth of the rays, half pixels around the best on all, then a parabola through the three
// best. The geometry's own conventions (rotation direction, detector orientation) come in
// through its ray functions, so nothing here assumes them.
#pragma once

#include <cstddef>
#include <optional>

#include "riner/scan.hpp"

namespace riner::preprocessing {

struct ConjugateAxis {
  double offset_px = 0.0;  // the detector offset (geometry's u) that puts the axis there
  std::size_t rays = 0;    // ray pairs compared at the best offset of the half-pixel grid
  bool half_acquisition = false;  // found beyond the detector's central half
};

// Fan beam (2D). Searches the geometry's offset +- search_px; where the geometry puts the axis
// in the detector's central half, also the offsets beyond it (a half acquisition: the axis near
// one end, only the rays around it have conjugates on the detector), by the mismatch relative
// to the spread of the readings compared, taken where that is under a quarter of the best
// around the geometry's offset. nullopt when the views do not cover a full turn less two steps,
// evenly spaced (within 10% of the step), or the detector is under 8 elements.
std::optional<ConjugateAxis> conjugate_axis(const Scan& scan, double search_px = 32.0);

}  // namespace riner::preprocessing
