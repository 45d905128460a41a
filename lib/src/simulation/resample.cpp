#include "riner/resample.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "riner/error.hpp"

namespace riner {

namespace {

// Where each of an axis's n_grid voxel centres (voxel mm apart, centred) falls on the image's
// n_image voxel centres (spacing mm apart, centred): between `lo` and `hi`, weight `w` on
// `hi`; outside beyond half an image voxel past the outermost centres (edge voxels extend to
// their outer faces unchanged).
struct Tap {
  bool inside = false;
  std::size_t lo = 0;
  std::size_t hi = 0;
  double w = 0.0;
};

std::vector<Tap> axis_taps(std::size_t n_grid, double voxel, std::size_t n_image, double spacing) {
  std::vector<Tap> taps(n_grid);
  const double last = static_cast<double>(n_image) - 1.0;
  for (std::size_t k = 0; k < n_grid; ++k) {
    const double mm = (static_cast<double>(k) - 0.5 * (static_cast<double>(n_grid) - 1.0)) * voxel;
    const double index = mm / spacing + 0.5 * last;
    if (index < -0.5 || index > last + 0.5) continue;
    const double clamped = std::clamp(index, 0.0, last);
    const std::size_t lo =
        std::min(static_cast<std::size_t>(clamped), n_image > 1 ? n_image - 2 : 0);
    taps[k] = {true, lo, std::min(lo + 1, n_image - 1), clamped - static_cast<double>(lo)};
  }
  return taps;
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
  const std::size_t nz = rank == 3 ? g.volume_shape[0] : 1;
  const std::size_t ny = g.volume_shape[rank - 2];
  const std::size_t nx = g.volume_shape[rank - 1];
  // Row 0 at +y (docs/guide/scans.md, "Geometry convention") in both grids: rows map to rows. A 2D
  // image is one slice.
  const std::vector<Tap> tz =
      rank == 3 ? axis_taps(nz, g.voxel_mm, sz, spacing_mm[0]) : std::vector<Tap>{{true}};
  const std::vector<Tap> ty = axis_taps(ny, g.voxel_mm, sy, spacing_mm[rank - 2]);
  const std::vector<Tap> tx = axis_taps(nx, g.voxel_mm, sx, spacing_mm[rank - 1]);
  auto at = [&](std::size_t z, std::size_t y, std::size_t x) {
    return static_cast<double>(image.data[(z * sy + y) * sx + x]);
  };
  Array out(g.volume_shape, 0.0f);
  for (std::size_t k = 0; k < nz; ++k) {
    for (std::size_t i = 0; i < ny; ++i) {
      for (std::size_t j = 0; j < nx; ++j) {
        const Tap& z = tz[k];
        const Tap& y = ty[i];
        const Tap& x = tx[j];
        if (!z.inside || !y.inside || !x.inside) continue;
        auto plane = [&](std::size_t zz) {
          return (1 - y.w) * ((1 - x.w) * at(zz, y.lo, x.lo) + x.w * at(zz, y.lo, x.hi)) +
                 y.w * ((1 - x.w) * at(zz, y.hi, x.lo) + x.w * at(zz, y.hi, x.hi));
        };
        out.data[(k * ny + i) * nx + j] =
            static_cast<float>((1 - z.w) * plane(z.lo) + z.w * plane(z.hi));
      }
    }
  }
  return out;
}

}  // namespace riner
