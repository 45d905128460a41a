// Joseph's method on the CPU, in double: a ray is walked one voxel plane at a time along its
// dominant axis, and at each plane the volume is interpolated (linearly in 2D, bilinearly in 3D)
// between the voxel centres around the crossing point; voxels outside the grid count as 0.
// The walk reports (voxel index, weight) pairs, so the projector (sum of weight * value) and its
// exact adjoint (scatter of weight * residual) share one traversal.
// kernels/joseph.cl is the device copy.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "riner/geometry.hpp"
#include "riner/rays.hpp"

namespace riner::ref {

// Grid extents in index space: (k, i, l) = (column, row, slice); row 0 is the top (y > 0).
struct GridIndexSpace {
  double nx = 1, ny = 1, nz = 1;
  double voxel = 1;
  bool is_3d = false;

  explicit GridIndexSpace(const Geometry& g) : voxel(g.voxel_mm), is_3d(g.is_3d()) {
    const std::size_t r = g.volume_shape.size();
    nx = static_cast<double>(g.volume_shape[r - 1]);
    ny = static_cast<double>(g.volume_shape[r - 2]);
    nz = is_3d ? static_cast<double>(g.volume_shape[0]) : 1.0;
  }
  // World point -> continuous index coordinates (k, i, l).
  void to_index(const Vec3& p, double out[3]) const {
    out[0] = p.x / voxel + 0.5 * (nx - 1.0);
    out[1] = 0.5 * (ny - 1.0) - p.y / voxel;
    out[2] = is_3d ? p.z / voxel + 0.5 * (nz - 1.0) : 0.0;
  }
};

// Calls visit(flat_index, weight) for every voxel the ray's line integral touches; weights are
// in mm (interpolation weight times the ray length per plane).
template <typename Visit>
void joseph_walk(const GridIndexSpace& grid, const Ray& ray, Visit&& visit) {
  double o[3];
  grid.to_index(ray.origin, o);
  // Direction in index units per mm of ray.
  const double d[3] = {ray.direction.x / grid.voxel, -ray.direction.y / grid.voxel,
                       grid.is_3d ? ray.direction.z / grid.voxel : 0.0};
  const double n[3] = {grid.nx, grid.ny, grid.nz};
  const int axes = grid.is_3d ? 3 : 2;
  int main_axis = 0;
  for (int a = 1; a < axes; ++a) {
    if (std::fabs(d[a]) > std::fabs(d[main_axis])) main_axis = a;
  }
  if (d[main_axis] == 0.0) return;
  const double step_length = 1.0 / std::fabs(d[main_axis]);
  // Along the main axis, the other coordinates are affine in the plane index m:
  // c_a(m) = o_a + (m - o_main) * d_a / d_main.
  int other[2] = {-1, -1};
  for (int a = 0, k = 0; a < axes; ++a) {
    if (a != main_axis) other[k++] = a;
  }
  double slope[2] = {0, 0};
  double base[2] = {0, 0};
  double m_lo = 0.0;
  double m_hi = n[main_axis] - 1.0;
  for (int k = 0; k < axes - 1; ++k) {
    const int a = other[k];
    slope[k] = d[a] / d[main_axis];
    base[k] = o[a] - o[main_axis] * slope[k];
    // Only planes where -1 < c_a(m) < n_a can touch the grid.
    if (slope[k] == 0.0) {
      if (base[k] <= -1.0 || base[k] >= n[a]) return;
    } else {
      double lo = (-1.0 - base[k]) / slope[k];
      double hi = (n[a] - base[k]) / slope[k];
      if (lo > hi) std::swap(lo, hi);
      m_lo = std::max(m_lo, std::ceil(lo));
      m_hi = std::min(m_hi, std::floor(hi));
    }
  }
  const std::size_t stride[3] = {1, static_cast<std::size_t>(grid.nx),
                                 static_cast<std::size_t>(grid.nx * grid.ny)};
  for (double m = m_lo; m <= m_hi; m += 1.0) {
    const std::size_t main_offset = static_cast<std::size_t>(m) * stride[main_axis];
    if (axes == 2) {
      const double c = base[0] + m * slope[0];
      const double f = std::floor(c);
      const double w = c - f;
      const long c0 = static_cast<long>(f);
      const int a = other[0];
      // Both ends checked: rounding can put c on n itself at a near-zero slope (a view at 90
      // degrees), and the cell at n lies past the grid.
      if (c0 >= 0 && c0 < static_cast<long>(n[a]))
        visit(main_offset + c0 * stride[a], (1.0 - w) * step_length);
      if (c0 + 1 >= 0 && c0 + 1 < static_cast<long>(n[a]))
        visit(main_offset + (c0 + 1) * stride[a], w * step_length);
      continue;
    }
    const double c[2] = {base[0] + m * slope[0], base[1] + m * slope[1]};
    const double f[2] = {std::floor(c[0]), std::floor(c[1])};
    const double w[2] = {c[0] - f[0], c[1] - f[1]};
    const long c0[2] = {static_cast<long>(f[0]), static_cast<long>(f[1])};
    for (int dy = 0; dy < 2; ++dy) {
      const long j = c0[1] + dy;
      if (j < 0 || j >= static_cast<long>(n[other[1]])) continue;
      const double wy = dy ? w[1] : 1.0 - w[1];
      for (int dx = 0; dx < 2; ++dx) {
        const long i = c0[0] + dx;
        if (i < 0 || i >= static_cast<long>(n[other[0]])) continue;
        const double wx = dx ? w[0] : 1.0 - w[0];
        visit(main_offset + i * stride[other[0]] + j * stride[other[1]], wx * wy * step_length);
      }
    }
  }
}

}  // namespace riner::ref
