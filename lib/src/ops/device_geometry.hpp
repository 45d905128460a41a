// The host mirror of ScanGeometry (kernels/ray_geometry.cl) and the per-view rotation table.
#pragma once

#include <CL/cl.h>

#include <vector>

#include "riner/geometry.hpp"

namespace riner::ops {

// Same members, same order, all four bytes wide: identical layout on host and device.
struct DeviceGeometry {
  cl_int type;
  cl_int n_u;
  cl_int n_v;
  cl_int n_views;
  cl_float pitch_u;
  cl_float pitch_v;
  cl_float offset_u;
  cl_float offset_v;
  cl_float sod;
  cl_float odd;
  cl_float voxel;
  cl_int nx;
  cl_int ny;
  cl_int nz;
  cl_int is_3d;
  cl_float grid_z;  // Geometry::grid_centre_z_mm
};
static_assert(sizeof(DeviceGeometry) == 64, "must match ScanGeometry in ray_geometry.cl");

DeviceGeometry to_device(const Geometry& g);

// (cos, sin) of every view angle, computed in double.
std::vector<cl_float2> view_rotations(const Geometry& g);

// Rays in the full measurement: views * rows * elements; InputError (check_piece_size) where the
// readings pass the kernels' 32-bit signed indices.
cl_uint ray_count(const Geometry& g);
// Voxels in the whole grid; InputError (check_piece_size) past the kernels' 32-bit indices.
std::size_t checked_volume_size(const Geometry& g);

}  // namespace riner::ops
