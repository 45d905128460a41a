#include "rings/radial.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace riner::rings {

PixelRadii::PixelRadii(std::size_t ny, std::size_t nx, double step_px) : radii_(ny * nx) {
  const double cx = 0.5 * (static_cast<double>(nx) - 1.0);
  const double cy = 0.5 * (static_cast<double>(ny) - 1.0);
  for (std::size_t i = 0; i < ny; ++i) {
    for (std::size_t k = 0; k < nx; ++k) {
      radii_[i * nx + k] =
          std::hypot(static_cast<double>(k) - cx, static_cast<double>(i) - cy) / step_px;
    }
  }
}

std::size_t PixelRadii::nearest(std::size_t pixel) const {
  return static_cast<std::size_t>(std::lround(radii_[pixel]));
}

PixelRadii::Between PixelRadii::between(std::size_t pixel) const {
  const double r = radii_[pixel];
  const auto lower = static_cast<std::size_t>(r);
  return {lower, r - static_cast<double>(lower)};
}

std::size_t PixelRadii::nearest_nodes() const {
  std::size_t nodes = 0;
  for (std::size_t p = 0; p < radii_.size(); ++p) nodes = std::max(nodes, nearest(p) + 1);
  return nodes;
}

std::vector<double> PixelRadii::angular_means(const std::vector<float>& values,
                                              std::size_t nodes) const {
  std::vector<double> sum(nodes, 0.0);
  std::vector<double> weight(nodes, 0.0);
  for (std::size_t p = 0; p < radii_.size(); ++p) {
    const Between at = between(p);
    if (at.lower + 1 >= nodes) continue;
    sum[at.lower] += (1.0 - at.upper_weight) * values[p];
    weight[at.lower] += 1.0 - at.upper_weight;
    sum[at.lower + 1] += at.upper_weight * values[p];
    weight[at.lower + 1] += at.upper_weight;
  }
  for (std::size_t k = 0; k < nodes; ++k) sum[k] = weight[k] > 0.0 ? sum[k] / weight[k] : 0.0;
  return sum;
}

std::ptrdiff_t mirrored(std::ptrdiff_t j, std::ptrdiff_t n) {
  if (n == 1) return 0;
  const std::ptrdiff_t period = 2 * (n - 1);
  j %= period;
  if (j < 0) j += period;
  return j < n ? j : period - j;
}

bool within_reach(const std::vector<double>& radii, double radius, double reach) {
  return std::any_of(radii.begin(), radii.end(),
                     [&](double r) { return std::fabs(r - radius) <= reach; });
}

std::vector<double> gaussian_smooth(const std::vector<double>& values, double sigma, Ends ends,
                                    const std::vector<char>* use) {
  const auto n = static_cast<std::ptrdiff_t>(values.size());
  std::vector<double> out(values.size(), 0.0);
  const auto reach = static_cast<std::ptrdiff_t>(std::ceil(kGaussianReach * sigma));
  auto used = [&](std::ptrdiff_t j) {
    return use == nullptr || (*use)[static_cast<std::size_t>(j)];
  };
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    if (!used(i)) continue;
    if (reach == 0) {
      out[static_cast<std::size_t>(i)] = values[static_cast<std::size_t>(i)];
      continue;
    }
    double sum = 0.0;
    double weight = 0.0;
    for (std::ptrdiff_t d = -reach; d <= reach; ++d) {
      std::ptrdiff_t j = i + d;
      if (ends == Ends::kMirror) j = mirrored(j, n);
      if (j < 0 || j >= n || !used(j)) continue;
      const double w = std::exp(-0.5 * static_cast<double>(d * d) / (sigma * sigma));
      sum += w * values[static_cast<std::size_t>(j)];
      weight += w;
    }
    out[static_cast<std::size_t>(i)] = sum / weight;
  }
  return out;
}

std::vector<std::pair<std::size_t, double>> gaussian_weights_at(
    const std::vector<double>& positions, double x, double sigma, const std::vector<char>* use) {
  std::vector<std::pair<std::size_t, double>> out;
  for (std::size_t f = 0; f < positions.size(); ++f) {
    if (use && !(*use)[f]) continue;
    const double t = (positions[f] - x) / sigma;
    if (std::fabs(t) > kGaussianReach) continue;
    out.emplace_back(f, std::exp(-0.5 * t * t));
  }
  return out;
}

double gaussian_mean_at(const std::vector<double>& positions, const std::vector<double>& values,
                        const std::vector<char>& use, double x, double sigma) {
  double sum = 0.0;
  double weight = 0.0;
  for (const auto& [f, w] : gaussian_weights_at(positions, x, sigma, &use)) {
    sum += w * values[f];
    weight += w;
  }
  return weight > 0.0 ? sum / weight : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace riner::rings
