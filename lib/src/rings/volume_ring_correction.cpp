#include "riner/volume_ring_correction.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "riner/error.hpp"
#include "riner/ring_chain.hpp"

namespace riner {

namespace {

// A row counts as the slice's when its height is within this fraction of a row pitch.
constexpr double kRowTolerance = 1e-3;

}  // namespace

std::vector<long> rows_of_slices(const Geometry& g) {
  if (g.type != GeometryType::kParallel3d) return {};
  const std::size_t nz = g.volume_shape[0];
  std::vector<long> rows(nz, -1);
  for (std::size_t s = 0; s < nz; ++s) {
    const double z = (static_cast<double>(s) - 0.5 * (static_cast<double>(nz) - 1.0)) * g.voxel_mm +
                     g.grid_centre_z_mm;
    const double r = z / g.pitch_v + 0.5 * (static_cast<double>(g.n_v) - 1.0) - g.offset_v;
    const double nearest = std::round(r);
    if (std::fabs(r - nearest) <= kRowTolerance && nearest >= 0.0 &&
        nearest < static_cast<double>(g.n_v)) {
      rows[s] = static_cast<long>(nearest);
    }
  }
  return rows;
}

VolumeRingCorrection correct_rings_per_slice(const Array& volume, const Array& alpha,
                                             const Geometry& g,
                                             const std::vector<std::size_t>& dead_elements,
                                             const RingCorrectionConfig& config,
                                             const std::vector<std::uint8_t>& sampled) {
  if (!g.is_3d()) throw InputError("per-slice ring correction: only 3D geometries");
  if (volume.shape != g.volume_shape) {
    throw InputError("per-slice ring correction: volume shape " + shape_string(volume.shape) +
                     " is not the geometry's grid " + shape_string(g.volume_shape));
  }
  const std::size_t pixels = g.n_u * g.n_v;
  if (alpha.size() != pixels) {
    throw InputError("per-slice ring correction: alpha has " + std::to_string(alpha.size()) +
                     " values for " + std::to_string(pixels) + " detector pixels");
  }
  if (!sampled.empty() && sampled.size() != volume.size()) {
    throw InputError("per-slice ring correction: the sampled-voxel mask has " +
                     std::to_string(sampled.size()) + " values for a volume of " +
                     std::to_string(volume.size()));
  }
  VolumeRingCorrection out;
  out.image = volume;
  out.alpha = alpha;
  if (g.type != GeometryType::kParallel3d) {
    out.note = "cone beam: a detector row's rays cross many slices, so no slice is a 2D scan";
    return out;
  }
  const std::vector<long> rows = rows_of_slices(g);
  const Geometry slice_g = axial_slice_geometry(g);
  const std::size_t ny = g.volume_shape[1];
  const std::size_t nx = g.volume_shape[2];
  std::vector<std::vector<std::size_t>> dead_by_row(g.n_v);
  for (std::size_t e : dead_elements) {
    if (e >= pixels) {
      throw InputError("per-slice ring correction: dead element " + std::to_string(e) +
                       " of a detector with " + std::to_string(pixels) + " pixels");
    }
    dead_by_row[e / g.n_u].push_back(e % g.n_u);
  }
  double change_sum = 0.0;
  for (std::size_t s = 0; s < rows.size(); ++s) {
    if (rows[s] < 0) continue;
    const auto row = static_cast<std::size_t>(rows[s]);
    ++out.slices;
    Array image({ny, nx});
    std::copy_n(volume.data.begin() + static_cast<std::ptrdiff_t>(s * ny * nx), ny * nx,
                image.data.begin());
    Array response({g.n_u});
    std::copy_n(alpha.data.begin() + static_cast<std::ptrdiff_t>(row * g.n_u), g.n_u,
                response.data.begin());
    std::vector<std::uint8_t> slice_sampled;
    if (!sampled.empty()) {
      const auto first = sampled.begin() + static_cast<std::ptrdiff_t>(s * ny * nx);
      slice_sampled.assign(first, first + static_cast<std::ptrdiff_t>(ny * nx));
    }
    const RingChain chain =
        correct_rings_in_order(image, response, slice_g, dead_by_row[row], config, slice_sampled);
    out.air_applied += chain.air && chain.air->applied;
    out.gradient_applied += chain.gradient && chain.gradient->applied;
    out.response_applied += chain.response && chain.response->applied;
    out.gradient_after_response_applied +=
        chain.gradient_after_response && chain.gradient_after_response->applied;
    out.mirror_applied += chain.mirror && chain.mirror->applied;
    std::copy(chain.image.data.begin(), chain.image.data.end(),
              out.image.data.begin() + static_cast<std::ptrdiff_t>(s * ny * nx));
    std::copy(chain.alpha.data.begin(), chain.alpha.data.end(),
              out.alpha.data.begin() + static_cast<std::ptrdiff_t>(row * g.n_u));
    for (std::size_t e = 0; e < g.n_u; ++e) {
      if (response.data[e] > 0.0f && chain.alpha.data[e] > 0.0f) {
        change_sum +=
            std::fabs(std::log(static_cast<double>(chain.alpha.data[e]) / response.data[e]));
      }
    }
  }
  if (out.slices == 0) {
    out.note = "no slice lies at a detector row's height (voxel size against row pitch, offset)";
    return out;
  }
  out.mean_response_change = change_sum / static_cast<double>(out.slices * g.n_u);
  return out;
}

}  // namespace riner
