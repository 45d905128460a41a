#include "riner/resample.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "riner/error.hpp"

namespace riner {

namespace {

// Where a grid coordinate (mm from the centre) falls on one axis of the image: the lower of
// the two voxel centres around it and the weight of the upper one; false beyond half a voxel
// outside the outermost centres. Edge voxels extend to their outer faces unchanged.
bool locate(double mm, double spacing, std::size_t n, std::size_t& lower, double& w) {
  const double index = mm / spacing + 0.5 * (static_cast<double>(n) - 1.0);
  if (index < -0.5 || index > static_cast<double>(n) - 0.5) return false;
  const double clamped = std::clamp(index, 0.0, static_cast<double>(n) - 1.0);
  lower = std::min(static_cast<std::size_t>(clamped), n > 1 ? n - 2 : 0);
  w = n > 1 ? clamped - static_cast<double>(lower) : 0.0;
  return true;
}

}  // namespace

Array resample_to_grid(const Array& image, const std::vector<double>& spacing_mm,
                       const Geometry& g) {
  const std::size_t rank = g.volume_shape.size();
  if (image.rank() != rank) {
    throw InputError("resample: a " + std::to_string(image.rank()) + "D image for a " +
                     std::to_string(rank) + "D grid");
  }
  if (spacing_mm.size() != rank) {
    throw InputError("resample: " + std::to_string(spacing_mm.size()) + " spacings for a " +
                     std::to_string(rank) + "D image");
  }
  for (double s : spacing_mm) {
    if (!(s > 0.0) || !std::isfinite(s)) throw InputError("resample: spacings must be > 0");
  }
  if (image.size() == 0) throw InputError("resample: the image is empty");
  // Work in 3D: a 2D image is one slice.
  const std::size_t sz = rank == 3 ? image.shape[0] : 1;
  const std::size_t sy = image.shape[rank - 2];
  const std::size_t sx = image.shape[rank - 1];
  const double dz = rank == 3 ? spacing_mm[0] : 1.0;
  const double dy = spacing_mm[rank - 2];
  const double dx = spacing_mm[rank - 1];
  const std::size_t nz = rank == 3 ? g.volume_shape[0] : 1;
  const std::size_t ny = g.volume_shape[rank - 2];
  const std::size_t nx = g.volume_shape[rank - 1];
  auto at = [&](std::size_t z, std::size_t y, std::size_t x) {
    return static_cast<double>(image.data[(z * sy + y) * sx + x]);
  };
  Array out(g.volume_shape, 0.0f);
  for (std::size_t k = 0; k < nz; ++k) {
    std::size_t z0 = 0;
    double wz = 0.0;
    const double mz = (static_cast<double>(k) - 0.5 * (static_cast<double>(nz) - 1.0)) * g.voxel_mm;
    if (rank == 3 && !locate(mz, dz, sz, z0, wz)) continue;
    const std::size_t z1 = std::min(z0 + 1, sz - 1);
    for (std::size_t i = 0; i < ny; ++i) {
      std::size_t y0 = 0;
      double wy = 0.0;
      // Row 0 at +y (README, "Geometry convention") in both grids: rows map to rows.
      const double my =
          (static_cast<double>(i) - 0.5 * (static_cast<double>(ny) - 1.0)) * g.voxel_mm;
      if (!locate(my, dy, sy, y0, wy)) continue;
      const std::size_t y1 = std::min(y0 + 1, sy - 1);
      for (std::size_t j = 0; j < nx; ++j) {
        std::size_t x0 = 0;
        double wx = 0.0;
        const double mx =
            (static_cast<double>(j) - 0.5 * (static_cast<double>(nx) - 1.0)) * g.voxel_mm;
        if (!locate(mx, dx, sx, x0, wx)) continue;
        const std::size_t x1 = std::min(x0 + 1, sx - 1);
        auto plane = [&](std::size_t z) {
          return (1 - wy) * ((1 - wx) * at(z, y0, x0) + wx * at(z, y0, x1)) +
                 wy * ((1 - wx) * at(z, y1, x0) + wx * at(z, y1, x1));
        };
        out.data[(k * ny + i) * nx + j] = static_cast<float>((1 - wz) * plane(z0) + wz * plane(z1));
      }
    }
  }
  return out;
}

}  // namespace riner
