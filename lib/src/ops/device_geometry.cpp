#include "ops/device_geometry.hpp"

#include <cmath>

#include "riner/array.hpp"

namespace riner::ops {

DeviceGeometry to_device(const Geometry& g) {
  const std::size_t rank = g.volume_shape.size();
  DeviceGeometry d{};
  d.type = static_cast<cl_int>(g.type);
  d.n_u = static_cast<cl_int>(g.n_u);
  d.n_v = static_cast<cl_int>(g.is_3d() ? g.n_v : 1);
  d.n_views = static_cast<cl_int>(g.n_views());
  d.pitch_u = static_cast<cl_float>(g.pitch_u);
  d.pitch_v = static_cast<cl_float>(g.pitch_v);
  d.offset_u = static_cast<cl_float>(g.offset_u);
  d.offset_v = static_cast<cl_float>(g.offset_v);
  d.sod = static_cast<cl_float>(g.source_origin_mm);
  d.odd = static_cast<cl_float>(g.origin_detector_mm);
  d.voxel = static_cast<cl_float>(g.voxel_mm);
  d.nx = static_cast<cl_int>(g.volume_shape[rank - 1]);
  d.ny = static_cast<cl_int>(g.volume_shape[rank - 2]);
  d.nz = static_cast<cl_int>(g.is_3d() ? g.volume_shape[0] : 1);
  d.is_3d = g.is_3d() ? 1 : 0;
  d.grid_z = static_cast<cl_float>(g.is_3d() ? g.grid_centre_z_mm : 0.0);
  return d;
}

std::vector<cl_float2> view_rotations(const Geometry& g) {
  std::vector<cl_float2> table(g.n_views());
  for (std::size_t i = 0; i < g.n_views(); ++i) {
    table[i].s[0] = static_cast<cl_float>(std::cos(g.angles[i]));
    table[i].s[1] = static_cast<cl_float>(std::sin(g.angles[i]));
  }
  return table;
}

cl_uint ray_count(const Geometry& g) {
  // The voxels each op checks itself: FBP by slabs keeps the whole grid, filling a slab's slices.
  const double readings = reading_count(g);
  check_piece_size(readings, 0.0, "the scan");
  return static_cast<cl_uint>(readings);
}

std::size_t checked_volume_size(const Geometry& g) {
  check_piece_size(0.0, voxel_count(g), "the volume");
  return shape_size(g.volume_shape);
}

}  // namespace riner::ops
