// Where the object can be, from the measurements alone, so that training skips the samples in
// the air around it (METHOD.md §2: "skip what a scene doesn't need"), and the image is zero
// there. A ray that measured no more than the noise above its element's offset (-ln alpha)
// crossed nothing: every voxel it passes through is air (the visual hull of space carving).
//
// - An element's offset is the low end of its readings over the views (its minimum plus one
//   noise sigma). Only elements whose readings look like pure air in every view (tight spread,
//   the scan's edges) set the noise and the range of plausible offsets; an element whose
//   lowest reading is outside that range (it never sees past the object) certifies nothing.
//   No such elements (a truncated scan, the object wider than the detector): no carving. An
//   air reading must also be a plausible -ln alpha (|offset| <= 0.5), and air must read 0 on
//   average (flat-field normalised, |median| <= 0.1): readings that are steady over the views
//   but larger come from an object centred on the axis (it projects alike in every view).
// - A voxel is air when, in some view, every element its footprint covers (the voxel's
//   shadow, interpolation included) reads certified air at that view.
// - The region is dilated by a margin; rays keep the samples from their first to their last
//   inside it (the same sample points, fewer of them).
// Wrongly carved object can only be object whose whole ray attenuation is below the noise
// threshold: a sliver at a convex surface, which the margin covers.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "model/ray_segments.hpp"
#include "riner/scan.hpp"

namespace riner::model {

struct OccupancySettings {
  double noise_sigmas = 4.0;  // a reading within this many noise sigmas of its offset is air
  int margin_px = 4;          // voxels of dilation around what the rays did not carve
};

struct Occupancy {
  bool carved = false;               // false: everything counts as inside (no evidence)
  std::vector<std::uint8_t> inside;  // per voxel, C order of the grid (1: sampled, kept)
  double inside_fraction = 1.0;
  double noise = 0.0;              // the readings' noise sigma (rho units), from the air elements
  std::size_t air_elements = 0;    // elements that read air in every view
  double air_offset_median = 0.0;  // their readings' typical level (-ln alpha; 0 when flat)
  std::string note;                // why no carving, when carved is false
};

Occupancy carve_occupancy(const Scan& scan, const OccupancySettings& settings);

// The image on the region as the output shows it: 0 in the air training skipped and, over the
// region's outermost `taper_px` voxels (the margin's outer part, air the readings certified
// too), a linear ramp down to that 0. A hard step at the margin's outline would leave its
// corners as isolated pixels above the dark air (measured: the HTC disc's "specks").
void fade_into_skipped_air(const Occupancy& occupancy, const std::vector<std::size_t>& shape,
                           int taper_px, std::vector<float>& image);

// The taper the margin leaves room for: half of it, at most 2 voxels.
inline int air_taper_px(int margin_px) { return margin_px >= 4 ? 2 : margin_px / 2; }

// Keeps each segment's samples from its first to its last inside the region (none when it
// misses it: count 0). Returns the samples left, summed over all rays.
double clip_segments(std::vector<RaySegment>& segments, const Geometry& g,
                     const Occupancy& occupancy, double spacing_voxels);

}  // namespace riner::model
