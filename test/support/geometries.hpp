// Small geometries of every type for tests; the paper presets are in riner/simulate.hpp.
#pragma once

#include <cmath>

#include "riner/geometry.hpp"

namespace riner::test {

inline Geometry make_geometry(GeometryType type, std::size_t n_views, std::size_t n_u,
                              std::size_t n_v, std::vector<std::size_t> volume, double pitch,
                              double voxel, double range = 2.0 * M_PI) {
  Geometry g;
  g.type = type;
  g.n_u = n_u;
  g.n_v = n_v;
  g.pitch_u = pitch;
  g.pitch_v = pitch;
  g.voxel_mm = voxel;
  g.volume_shape = std::move(volume);
  if (g.is_divergent()) {
    g.source_origin_mm = 4.0 * voxel * static_cast<double>(g.volume_shape.back());
    g.origin_detector_mm = 2.0 * voxel * static_cast<double>(g.volume_shape.back());
  }
  g.uniform_angles = UniformAngles{n_views, 0.1, range};
  g.angles = uniform_angles(*g.uniform_angles);
  g.validate();
  return g;
}

// A 2D fan beam whose detector covers a 64 x 64 grid with margin.
inline Geometry small_fan2d() {
  return make_geometry(GeometryType::kFan2d, 90, 97, 1, {64, 64}, 1.5, 1.0);
}
inline Geometry small_parallel2d() {
  return make_geometry(GeometryType::kParallel2d, 60, 95, 1, {61, 67}, 1.0, 1.0, M_PI);
}
inline Geometry small_cone3d() {
  return make_geometry(GeometryType::kCone3d, 40, 61, 37, {24, 40, 40}, 1.5, 1.0);
}
inline Geometry small_parallel3d() {
  return make_geometry(GeometryType::kParallel3d, 30, 47, 21, {20, 32, 32}, 1.0, 1.0, M_PI);
}

// `g` with `views` angles stepping evenly over `range` radians from 0.3 (with or without the
// endpoint), listed (no uniform form).
inline Geometry with_angles(Geometry g, std::size_t views, double range, bool endpoint) {
  g.uniform_angles.reset();
  g.angles.clear();
  const double step = range / static_cast<double>(endpoint ? views - 1 : views);
  for (std::size_t i = 0; i < views; ++i) g.angles.push_back(0.3 + step * static_cast<double>(i));
  return g;
}

}  // namespace riner::test
