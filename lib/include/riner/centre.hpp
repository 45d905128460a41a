// Where the rotation axis projects on the detector, from the scan itself: a parallel-beam view
// and the view half a turn later are mirror images of each other about the axis. Two ways to
// read it: the whole sinogram (the first half-turn and its mirror image make one unbroken
// full-turn sinogram only about the axis: Vo et al. 2014, lib/src/preprocessing/
// centre_sinogram.hpp), and view pairs (the axis where each view and its opposite match best).
// The sinogram uses every view, so one noisy or dim view moves it little, and it needs no exact
// pair (a 179.5-degree scan); the pairs are its cross-check, and the answer when the views do
// not cover an evenly spaced half-turn.
#pragma once

#include <cstddef>
#include <string>

#include "riner/scan.hpp"

namespace riner {

struct CentreEstimate {
  double offset_px = 0.0;    // the geometry's detector offset (u) that puts the axis there
  double axis_column = 0.0;  // the detector column (0-based, fractional) the axis projects to
  // The spread of the estimates of the single view pairs (standard deviation, px): small when
  // they agree. With one pair, the width of the matching cost's minimum instead.
  double spread_px = 0.0;
  // View pairs half a turn apart that were compared (conjugate rays: the ray pairs).
  std::size_t pairs = 0;
  std::size_t rows = 0;   // detector rows compared (1 in 2D)
  std::string method;     // "sinogram", "view pairs" or "view pairs, half acquisition"
  // A full turn whose axis lies beyond the central search, near one end of the detector.
  bool half_acquisition = false;
  // Each method's own answer (NaN where it has none): the cross-check.
  double sinogram_offset_px = 0.0;
  double pairs_offset_px = 0.0;
};

// Parallel beam (2D or 3D). The sinogram where the views cover an evenly spaced half-turn less
// 4 steps (179.5 degrees of 180 views; 178 of 100); else view pairs half a turn apart: exactly
// (within a quarter of the mean angular step) or between two views (interpolated in angle; a
// 360-degree scan with an odd number of views). Non-finite readings are left out (pairs) or
// interpolated along the row (sinogram). InputError for a divergent beam or a scan where neither
// works. Fan beam (2D) over a full turn: from conjugate rays (method "conjugate rays",
// preprocessing/centre_conjugate.hpp), within 32 px of the geometry's offset, or a half
// acquisition's beyond the detector's central half ("conjugate rays, half acquisition"); a cone
// beam likewise from the fan of its rays through the source's plane.
CentreEstimate estimate_centre(const Scan& scan);

// A parallel beam's centre finders search offsets within this share of the detector's width
// either way of its middle. Over a full turn the view pairs also search beyond, up to where a
// view and its opposite share a twentieth of the detector (16 columns at least): a half
// acquisition's axis, taken where it matches far better than the central best, relative to the
// spread of the readings compared.
constexpr double kCentreSearchShare = 0.25;

// Whether estimate_centre searches where the geometry puts the axis: a divergent beam's search
// follows the geometry's offset, a parallel beam's covers the detector over a full turn and
// stays within kCentreSearchShare otherwise.
bool centre_search_covers(const Geometry& g);

}  // namespace riner
