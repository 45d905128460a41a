// Where the object can be, from the measurements alone, so that training skips the samples in
// the air around it (METHOD.md §2: "skip what a scene doesn't need"), and the image is zero
// there. Skipping object is the worst thing the tool can do (the image says "nothing here"), so
// a voxel is skipped only on evidence that holds against the noise, an outlier view and a
// centre of rotation a few pixels off (issue 29; docs/history/RESULTS.md):
//
// 1. Readings that certify air (model/air_readings.hpp): within the noise of their element's
//    offset, as the mean of three neighbouring rays; outlier views certify nothing.
// 2. Rays: a voxel is air when, in at least `min_views` views, every element its footprint
//    covers (the voxel's shadow, interpolation included, widened along the row by
//    `centre_tolerance_px` elements) reads certified air (space carving's visual hull). A centre
//    of rotation off by d pixels shrinks the hull by d on every side: the FBP check (it sees the
//    object a few pixels off as well) and the margin hold it up to 5 pixels on the simulated
//    squares (the 640-column one: not at 8); the widening holds it by construction, for more
//    samples (0 by default).
// 3. The FBP (model/object_seen_by_fbp.hpp): every voxel the scan's binned FBP clearly sees as
//    object is kept, whatever the rays said. A ray grazing a faint corner reads like air; the
//    FBP sums every view there and sees the corner.
// 4. Rays through the skipped air, the check of what was skipped: a ray that crosses the grid
//    but misses the kept region (grown by the margin) must read air. Reported, not acted on:
//    the faint matter in DeepLesion's air reads up to 13 sigma (keeping it for training cost
//    0.1-0.5 dB per slice), and it is blind where it matters most: with the centre 8 or 12 px
//    off, the 640-column square loses 283-3060 pixels and no ray near them reads above air.
// 5. The region is grown by a margin; rays keep the samples from their first to their last
//    inside it (the same sample points, fewer of them).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "model/ray_segments.hpp"
#include "riner/device.hpp"
#include "riner/engine.hpp"
#include "riner/riner_config.hpp"
#include "riner/scan.hpp"

namespace riner::model {

struct OccupancySettings {
  double noise_sigmas = 4.0;         // a reading (mean of three) within this many sigmas is air
  int margin_px = 4;                 // voxels of dilation around what the rays did not carve
  int min_views = 3;                 // views that must certify a voxel's shadow
  double centre_tolerance_px = 0.0;  // each shadow widened by this many elements either side
  bool fbp_check = true;             // keep what the FBP sees (3.)
  double fbp_sigmas = 5.0;           // object in the FBP: this many of its noise sigmas above air
  double ray_check_sigmas = 5.0;     // a skipped ray reading more than this has found object (4.);
                                     // more where so many rays are checked that noise would
  Engine engine = Engine::kOpenCL;   // of the FBP check
  std::optional<Device> device;      // OpenCL: default Device::open()
};

// A run's settings: its training.air_* (air_fbp_check auto: on in 2D), the FBP check on `engine`
// (OpenCL: on `device`, default Device::open()).
OccupancySettings occupancy_settings(const TrainingConfig& training, const Geometry& g,
                                     Engine engine, std::optional<Device> device);

struct Occupancy {
  bool carved = false;               // false: everything counts as inside (no evidence)
  std::vector<std::uint8_t> inside;  // per voxel, C order of the grid (1: sampled, kept)
  double inside_fraction = 1.0;
  double samples_kept = 0.0;       // of the segments carve_occupancy clipped, summed
  double noise = 0.0;              // the readings' noise sigma (rho units), from the air elements
  std::size_t air_elements = 0;    // elements that read air in every view
  double air_offset_median = 0.0;  // their readings' typical level (-ln alpha; 0 when flat)
  std::string note;                // why no carving, when carved is false
  std::size_t outlier_views = 0;   // views that certified nothing (dim, noisy)
  std::size_t fbp_bin = 0;         // the FBP check's binning (0: no check)
  double fbp_noise = 0.0;          // its blurred FBP's noise sigma in the carved air (1/mm)
  std::size_t kept_by_fbp = 0;     // voxels the rays carved and the FBP kept
  // Rays (checked: not from outlier views) that cross the grid but not the region, and the
  // largest mean excess over their offsets (of three neighbours) among them, in rho and in
  // noise sigmas of such a mean.
  std::size_t skipped_rays = 0;
  double skipped_ray_excess = 0.0;
  double skipped_ray_sigmas = 0.0;
  double ray_check_threshold = 0.0;    // noise sigmas (ray_check_sigmas or more)
  std::size_t skipped_rays_above = 0;  // reading more than that
  std::size_t skipped_rays_near = 0;   // of those, within the margin's width of the region
};

// `segments`: the scan's rays as training samples them (ray_segments), spacing in voxels; when
// the scan is carved they come back clipped to the region (clip_segments) and the rays that miss
// it (whose samples all do) are checked (4.).
Occupancy carve_occupancy(const Scan& scan, RaySegments& segments, double spacing_voxels,
                          const OccupancySettings& settings);

// The same with the rays sampled every 1.5 voxels across the whole grid.
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
double clip_segments(RaySegments& segments, const Scan& scan, const Occupancy& occupancy,
                     double spacing_voxels);

}  // namespace riner::model
