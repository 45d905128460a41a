// The voxels whose rays read no light in nearly every view: the full shadow of metal that
// stopped the beam. Training's bounds (model/starved_readings.hpp) are their only readings, and
// the metal's rim alone meets them, so the readings do not say what those voxels hold: a solid
// metal's middle (a 3/mm disc behind noisy darks read about 0 there under a rim of 1.8) or a
// hollow tube's water (a review's tube: raised to the rim's level, its water read 2.0 for 0.02).
// They are found and counted, not changed.
#pragma once

#include <cstddef>

#include "riner/array.hpp"
#include "riner/geometry.hpp"

namespace riner::model {

// A hull voxel: its ray is a bound (+inf after mark_starved_readings) in at least this share of
// the views whose reading it meets, and none of them reads under half the floor.
constexpr double kHullBoundShare = 0.95;

struct StoppedHull {
  std::size_t voxels = 0;  // in the hull
  double mean = 0.0;       // the image's mean there (what training left; 0: no hull)
};

// `readings`: the scan's measurement after mark_starved_readings (bounds +inf, unread NaN), of
// geometry g; `image` on g's grid.
StoppedHull find_stopped_hull(const Array& image, const Array& readings, const Geometry& g,
                              float floor);

}  // namespace riner::model
