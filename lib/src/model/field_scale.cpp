#include "model/field_scale.hpp"

#include <algorithm>
#include <cmath>

#include "riner/scan.hpp"

namespace riner::model {

double typical_mu(const Array& measurement, const Geometry& g) {
  const std::size_t across = g.is_3d() ? std::max(g.volume_shape[1], g.volume_shape[2])
                                       : std::max(g.volume_shape[0], g.volume_shape[1]);
  const double width_mm = static_cast<double>(across) * g.voxel_mm;
  if (!(width_mm > 0.0)) return 0.0;
  return median_view_largest(measurement, g.n_views()) / width_mm;
}

double field_per_mu(double mu) {
  if (!(mu > 0.0) || !std::isfinite(mu)) return 1.0;
  if (mu >= kLeastTypicalMu && mu <= kMostTypicalMu) return 1.0;
  return std::exp2(std::round(std::log2(kTargetTypicalMu / mu)));
}

Geometry lengths_divided(Geometry g, double factor) {
  g.pitch_u /= factor;
  g.pitch_v /= factor;
  g.source_origin_mm /= factor;
  g.origin_detector_mm /= factor;
  g.voxel_mm /= factor;
  g.grid_centre_z_mm /= factor;
  return g;
}

}  // namespace riner::model
