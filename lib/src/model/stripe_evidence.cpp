#include "model/stripe_evidence.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace riner::model {

std::vector<double> element_means(const Scan& scan) {
  const Geometry& g = scan.geometry;
  const std::size_t views = g.n_views();
  const std::size_t per_view = g.n_u * (g.is_3d() ? g.n_v : 1);
  std::vector<double> mean(per_view, 0.0);
  const std::vector<float>& rho = scan.measurement.data;
  for (std::size_t v = 0; v < views; ++v) {
    for (std::size_t e = 0; e < per_view; ++e) mean[e] += rho[v * per_view + e];
  }
  // A non-finite reading leaves its element's sum non-finite.
  for (double& m : mean) m = std::isfinite(m) ? m / static_cast<double>(views) : NAN;
  return mean;
}

double stripe_rms(const Scan& scan) { return stripe_rms(element_means(scan), scan.geometry.n_u); }

double stripe_rms(const std::vector<double>& means, std::size_t n_u) {
  constexpr std::size_t kWindow = 7;
  double squares = 0.0;
  std::size_t count = 0;
  std::vector<double> row;
  for (std::size_t r = 0; r < means.size() / n_u; ++r) {
    row.clear();
    for (std::size_t u = 0; u < n_u; ++u) {
      const double m = means[r * n_u + u];
      if (std::isfinite(m)) row.push_back(m);
    }
    if (row.size() < kWindow) continue;
    // Only where the window is centred: at a row's ends a sloping object would read as stripes.
    for (std::size_t i = kWindow / 2; i + kWindow / 2 < row.size(); ++i) {
      std::array<double, kWindow> window;
      std::copy(row.begin() + static_cast<std::ptrdiff_t>(i - kWindow / 2),
                row.begin() + static_cast<std::ptrdiff_t>(i + kWindow / 2 + 1), window.begin());
      std::nth_element(window.begin(), window.begin() + kWindow / 2, window.end());
      const double d = row[i] - window[kWindow / 2];
      squares += d * d;
      ++count;
    }
  }
  return count > 0 ? std::sqrt(squares / static_cast<double>(count)) : 0.0;
}

}  // namespace riner::model
