#include "model/chessboard_distance.hpp"

#include <algorithm>

namespace riner::model {

std::vector<std::uint16_t> chessboard_distance(const std::vector<std::uint8_t>& marked,
                                               const std::vector<std::size_t>& shape) {
  const std::size_t rank = shape.size();
  const long nx = static_cast<long>(shape[rank - 1]);
  const long ny = static_cast<long>(shape[rank - 2]);
  const long nz = rank == 3 ? static_cast<long>(shape[0]) : 1;
  std::vector<std::uint16_t> d(marked.size());
  for (std::size_t i = 0; i < marked.size(); ++i) d[i] = marked[i] ? 0 : kFarVoxels;
  // Two chamfer passes over all 3^rank - 1 neighbours: first those before each voxel in memory
  // order, then those after.
  for (int pass = 0; pass < 2; ++pass) {
    const long step = pass == 0 ? 1 : -1;
    const long z0 = pass == 0 ? 0 : nz - 1, y0 = pass == 0 ? 0 : ny - 1,
               x0 = pass == 0 ? 0 : nx - 1;
    for (long z = z0; z >= 0 && z < nz; z += step) {
      for (long y = y0; y >= 0 && y < ny; y += step) {
        for (long x = x0; x >= 0 && x < nx; x += step) {
          const std::size_t i = static_cast<std::size_t>((z * ny + y) * nx + x);
          std::uint32_t best = d[i];
          for (long dz = (rank == 3 ? -1 : 0); dz <= (rank == 3 ? 1 : 0); ++dz) {
            for (long dy = -1; dy <= 1; ++dy) {
              for (long dx = -1; dx <= 1; ++dx) {
                const long offset = (dz * ny + dy) * nx + dx;
                if (offset * step >= 0) continue;  // not yet visited in this pass
                const long zz = z + dz, yy = y + dy, xx = x + dx;
                if (zz < 0 || zz >= nz || yy < 0 || yy >= ny || xx < 0 || xx >= nx) continue;
                const std::size_t j = static_cast<std::size_t>((zz * ny + yy) * nx + xx);
                if (d[j] != kFarVoxels) best = std::min<std::uint32_t>(best, d[j] + 1u);
              }
            }
          }
          d[i] = static_cast<std::uint16_t>(std::min<std::uint32_t>(best, kFarVoxels));
        }
      }
    }
  }
  return d;
}

std::vector<std::uint8_t> dilated(const std::vector<std::uint8_t>& marked,
                                  const std::vector<std::size_t>& shape, int reach) {
  const std::vector<std::uint16_t> d = chessboard_distance(marked, shape);
  std::vector<std::uint8_t> out(marked.size());
  const auto limit = static_cast<std::uint32_t>(std::max(0, reach));
  for (std::size_t i = 0; i < out.size(); ++i) out[i] = d[i] <= limit;
  return out;
}

}  // namespace riner::model
