#include "preprocessing/stripes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "util/parallel.hpp"
#include "util/robust_statistics.hpp"

namespace riner::preprocessing {

std::vector<double> row_quantile(const std::vector<double>& values, std::size_t n_u,
                                 std::size_t reach, double q) {
  std::vector<double> out(values.size(), std::numeric_limits<double>::quiet_NaN());
  util::parallel_for(values.size(), [&](std::size_t begin, std::size_t end) {
    std::vector<double> near;
    for (std::size_t e = begin; e < end; ++e) {
      if (!std::isfinite(values[e])) continue;
      const std::size_t column = e % n_u;
      near.clear();
      for (std::size_t c = column >= reach ? column - reach : 0;
           c <= std::min(n_u - 1, column + reach); ++c) {
        const double v = values[e - column + c];
        if (std::isfinite(v)) near.push_back(v);
      }
      out[e] = util::quantile(near, q);
    }
  });
  return out;
}

void remove_stripes(Array& m, const Geometry& g, std::size_t reach) {
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
  for (std::size_t e = 0; e < per_view; ++e) {
    mean[e] = count[e] > 0.0 ? mean[e] / count[e] : std::numeric_limits<double>::quiet_NaN();
  }
  const std::vector<double> level = row_quantile(mean, g.n_u, reach, 0.5);
  std::vector<double> stripe(per_view, 0.0);
  for (std::size_t e = 0; e < per_view; ++e) {
    if (std::isfinite(mean[e])) stripe[e] = mean[e] - level[e];
  }
  for (std::size_t v = 0; v < views; ++v) {
    for (std::size_t e = 0; e < per_view; ++e) m.data[v * per_view + e] -= stripe[e];
  }
}

}  // namespace riner::preprocessing
