// Where a filtered backprojection of the scan clearly sees object: the check the air carving
// (model/occupancy.hpp) must pass before it may skip a voxel. A ray that grazes a faint corner
// reads within the noise of air, so the rays alone would carve it away; the FBP adds up every
// view's evidence at each point and sees it (a square of 6e-4/mm under neutron-like noise: 6.5
// noise sigma at 2x binning, where one ray's grazing reading is under 1).
//
// - The scan is binned by an integer factor along the detector (and the grid with it) so that
//   the grid's largest side is at most 512 in 2D, 128 in 3D: less noise and a fraction of the
//   time. Each binned element's stripe (its mean over the views less the running median of its
//   neighbours') is taken off first, so that rings do not pass for object.
// - FBP (Hann filter) on the binned grid, blurred by a Gaussian of one binned voxel.
// - Its noise: the median and the MAD over the binned voxels that the rays carved, at least 3
//   binned voxels from anything they kept, and that every view sees, once the rings left in
//   that air are taken off (its median at each radius, per axial slice).
// - Object: inside the region every view sees (beyond it the FBP is not an image of the object:
//   the rays and their check decide there), above the median by `sigmas` of that noise and by
//   1.5 times the deepest dip below it within 12 binned voxels (artifacts swing both ways: a
//   bright edge's ringing, rings, streaks; an object only up) and over 0.3 of the brightest
//   within 3 binned voxels (a bright edge's blur spills into the air beside it), and joined to
//   what the rays kept: an island out in the air is a streak's or a ring's bright spot far more
//   often than a separate faint object (which this check then leaves to the rays).
// - `object`: the voxels of that which the rays carved, grown by 4 voxels of the scan's grid (a
//   centre of rotation 5 pixels off blurs a faint corner below the threshold at its tip).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "riner/device.hpp"
#include "riner/engine.hpp"
#include "riner/scan.hpp"

namespace riner::model {

struct FbpCheckSettings {
  double sigmas = 5.0;
  Engine engine = Engine::kOpenCL;
  std::optional<Device> device;  // OpenCL: default Device::open()
};

struct ObjectSeenByFbp {
  bool usable = false;               // false: too little carved air to measure the FBP's noise
  std::vector<std::uint8_t> object;  // per voxel of the scan's grid: carved object, grown
  std::size_t bin = 1;               // the binning factor
  double noise = 0.0;                // the blurred FBP's noise sigma in the carved air (1/mm)
  double level = 0.0;                // its median there
  std::size_t air_voxels = 0;        // binned voxels the noise was measured on
};

// `kept`: per voxel of the grid, 1 where the rays did not carve.
ObjectSeenByFbp object_seen_by_fbp(const Scan& scan, const std::vector<std::uint8_t>& kept,
                                   const FbpCheckSettings& settings);

}  // namespace riner::model
