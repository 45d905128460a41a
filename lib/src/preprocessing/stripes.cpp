#include "preprocessing/stripes.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "util/robust_statistics.hpp"

namespace riner::preprocessing {

void remove_stripes(Array& m, const Geometry& g, long reach) {
  const std::size_t views = g.n_views(), per_view = m.size() / views;
  std::vector<double> mean(per_view, 0.0), count(per_view, 0.0);
  for (std::size_t v = 0; v < views; ++v) {
    for (std::size_t e = 0; e < per_view; ++e) {
      const float x = m.data[v * per_view + e];
      if (!std::isfinite(x)) continue;
      mean[e] += x;
      count[e] += 1.0;
    }
  }
  std::vector<double> stripe(per_view, 0.0), near;
  for (std::size_t e = 0; e < per_view; ++e) {
    if (count[e] == 0.0) continue;
    mean[e] /= count[e];
  }
  for (std::size_t e = 0; e < per_view; ++e) {
    if (count[e] == 0.0) continue;
    const long column = static_cast<long>(e % g.n_u);
    near.clear();
    for (long c = std::max(0L, column - reach);
         c <= std::min(static_cast<long>(g.n_u) - 1, column + reach); ++c) {
      const std::size_t k = e - static_cast<std::size_t>(column) + static_cast<std::size_t>(c);
      if (count[k] > 0.0) near.push_back(mean[k]);
    }
    stripe[e] = mean[e] - util::quantile(near, 0.5);
  }
  for (std::size_t v = 0; v < views; ++v) {
    for (std::size_t e = 0; e < per_view; ++e) m.data[v * per_view + e] -= stripe[e];
  }
}

}  // namespace riner::preprocessing
