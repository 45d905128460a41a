#include "model/noise_evidence.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "util/robust_statistics.hpp"

namespace riner::model {

namespace {

// A second difference of independent readings has variance 6 sigma^2.
const double kSecondDifferenceGain = std::sqrt(6.0);
// Enough readings for stable quantiles; a 3D scan is thinned evenly to about this many.
constexpr std::size_t kMostSamples = std::size_t{1} << 20;

}  // namespace

NoiseEvidence reading_noise(const Scan& scan) {
  const Geometry& g = scan.geometry;
  const std::size_t views = g.n_views();
  const std::size_t per_view = g.n_u * (g.is_3d() ? g.n_v : 1);
  NoiseEvidence e;
  if (views < 3 || per_view == 0) return e;
  const std::size_t stride = std::max<std::size_t>(1, (views - 2) * per_view / kMostSamples);
  const std::vector<float>& rho = scan.measurement.data;
  std::vector<double> differences, readings;
  for (std::size_t i = 0; i < (views - 2) * per_view; i += stride) {
    const std::size_t v = i / per_view + 1, element = i % per_view;
    const float a = rho[(v - 1) * per_view + element], b = rho[v * per_view + element],
                c = rho[(v + 1) * per_view + element];
    if (std::isfinite(b)) readings.push_back(b);
    if (std::isfinite(a) && std::isfinite(b) && std::isfinite(c))
      differences.push_back(std::fabs(static_cast<double>(a) - 2.0 * b + c));
  }
  if (differences.empty() || readings.empty()) return e;
  e.sigma = util::kMadToSigma * util::quantile(differences, 0.5) / kSecondDifferenceGain;
  e.level = util::quantile(readings, 0.99);
  e.relative = e.level > 0.0 ? e.sigma / e.level : 0.0;
  return e;
}

}  // namespace riner::model
