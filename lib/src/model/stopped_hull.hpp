// The voxels whose rays read no light in nearly every view: the shadow hull of metal that stopped
// the beam. Training's bounds (model/starved_readings.hpp) are their only readings, and the
// metal's rim alone meets them, so nothing holds the values inside: a 3/mm disc behind noisy
// darks read -0.15/mm in its middle under a rim of 1.8. They are shown at least at the hull's
// upper level, which is all their readings say.
#pragma once

#include <cstddef>

#include "riner/array.hpp"
#include "riner/geometry.hpp"

namespace riner::model {

// A hull voxel: its ray is a bound (+inf after mark_starved_readings) in at least this share of
// the views whose reading it meets, and none of them reads under half the floor.
constexpr double kHullBoundShare = 0.95;
// The level the hull is raised to: this quantile of the image over the hull.
constexpr double kHullLevelQuantile = 0.9;

struct StoppedHull {
  std::size_t voxels = 0;  // in the hull
  float level = 0.0f;      // the least a hull voxel now reads (0: no hull)
};

// `readings`: the scan's measurement after mark_starved_readings (bounds +inf, unread NaN), of
// geometry g; `image` on g's grid. Raises the hull's voxels below its level to it.
StoppedHull raise_stopped_hull(Array& image, const Array& readings, const Geometry& g, float floor);

}  // namespace riner::model
