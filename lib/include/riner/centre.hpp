// Where the rotation axis projects on the detector, from the scan itself: a parallel-beam view
// and the view half a turn later are mirror images of each other about the axis, so the axis
// is where the mirrored pair matches best.
#pragma once

#include <cstddef>

#include "riner/scan.hpp"

namespace riner {

struct CentreEstimate {
  double offset_px = 0.0;    // the geometry's detector offset (u) that puts the axis there
  double axis_column = 0.0;  // the detector column (0-based, fractional) the axis projects to
  // The spread of the estimates of the single view pairs (standard deviation, px): small when
  // they agree. With one pair, the width of the matching cost's minimum instead.
  double spread_px = 0.0;
  std::size_t pairs = 0;  // view pairs half a turn apart that were compared
  std::size_t rows = 0;   // detector rows compared (1 in 2D)
};

// Parallel beam (2D or 3D) with views half a turn after others: exactly (within a quarter of
// the mean angular step) or between two views (interpolated in angle; a 360-degree scan with an
// odd number of views). A 180-degree scan needs its endpoint view. Non-finite readings are left
// out. InputError for a divergent beam or a scan with no such views.
CentreEstimate estimate_centre(const Scan& scan);

}  // namespace riner
