#include "model/starved_readings.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "model/response_changes.hpp"
#include "riner/scan.hpp"

namespace riner::model {

namespace {

// The first finite reading from `from` on, stepping by `step` (-1: leftwards); NaN where none.
float nearest_finite(const float* line, long from, long step, long n) {
  for (long k = from; k >= 0 && k < n; k += step) {
    if (std::isfinite(line[k])) return line[k];
  }
  return NAN;
}

// Per reading: whether it lies in a run of at least `views_needed` consecutive views in which
// its element reads +inf.
std::vector<char> in_long_dark_run(const Array& m, std::size_t views, std::size_t views_needed) {
  const std::size_t per_view = m.size() / views;
  std::vector<char> out(m.size(), 0);
  for (std::size_t e = 0; e < per_view; ++e) {
    for (std::size_t v = 0; v < views;) {
      if (!is_starved(m.data[v * per_view + e])) {
        ++v;
        continue;
      }
      std::size_t w = v;
      while (w < views && is_starved(m.data[w * per_view + e])) ++w;
      if (w - v >= views_needed) {
        for (std::size_t k = v; k < w; ++k) out[k * per_view + e] = 1;
      }
      v = w;
    }
  }
  return out;
}

}  // namespace

StarvedReadings mark_starved_readings(Array& measurement, std::size_t views) {
  StarvedReadings out;
  if (measurement.size() == 0 || views == 0 || measurement.rank() < 2) return out;
  const float limit = largest_reading(measurement, views);
  float largest = 0.0f;
  for (float x : measurement.data) {
    if (std::isfinite(x) && std::fabs(x) <= limit) largest = std::max(largest, x);
  }
  const auto n = static_cast<long>(measurement.shape.back());
  const std::size_t lines = measurement.size() / static_cast<std::size_t>(n);
  const std::size_t per_view = measurement.size() / views;
  // An element that reads nothing in any view is dead, whatever its neighbours read.
  std::vector<char> reads(per_view, 0);
  for (std::size_t i = 0; i < measurement.size(); ++i) {
    if (std::isfinite(measurement.data[i])) reads[i % per_view] = 1;
  }
  const std::vector<char> dying =
      in_long_dark_run(measurement, views, response_change_min_views(views));
  const float bar = static_cast<float>(kStarvedNeighbourShare) * largest;
  for (std::size_t l = 0; l < lines; ++l) {
    const std::size_t at = l * static_cast<std::size_t>(n);
    float* line = measurement.ptr() + at;
    for (long k = 0; k < n;) {
      if (!is_starved(line[k])) {
        ++k;
        continue;
      }
      long end = k;
      while (end < n && is_starved(line[end])) ++end;
      const bool wide = static_cast<std::size_t>(end - k) > kWidestDeadRun;
      const bool dense_beside =
          nearest_finite(line, k - 1, -1, n) >= bar || nearest_finite(line, end, 1, n) >= bar;
      for (long j = k; j < end; ++j) {
        const std::size_t i = at + static_cast<std::size_t>(j);
        const bool stopped = wide || (dense_beside && !dying[i]);
        if (largest > 0.0f && stopped && reads[i % per_view]) {
          ++out.count;
        } else {
          line[j] = NAN;
        }
      }
      k = end;
    }
  }
  if (out.count > 0) out.floor = largest;
  return out;
}

}  // namespace riner::model
