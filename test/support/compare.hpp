// Element-wise comparison of a result against a reference, reporting the worst element.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <sstream>
#include <string>
#include <vector>

namespace riner::test {

struct ErrorStats {
  double max_abs = 0.0;
  double max_rel = 0.0;  // |a-b| / max(|b|, floor)
  double rms_rel = 0.0;  // ||a-b|| / ||b||
  std::size_t worst = 0;
  std::size_t non_finite = 0;

  std::string describe() const {
    std::ostringstream s;
    s << "max_abs " << max_abs << ", max_rel " << max_rel << ", rms_rel " << rms_rel
      << ", worst at " << worst << ", non-finite " << non_finite;
    return s.str();
  }
};

template <typename A, typename B>
ErrorStats compare(const A& got, const B& want, double floor = 1e-6) {
  ErrorStats stats;
  double diff_sq = 0.0;
  double ref_sq = 0.0;
  const std::size_t n = std::min<std::size_t>(got.size(), want.size());
  for (std::size_t i = 0; i < n; ++i) {
    const double a = static_cast<double>(got[i]);
    const double b = static_cast<double>(want[i]);
    if (!std::isfinite(a) || !std::isfinite(b)) {
      ++stats.non_finite;
      continue;
    }
    const double d = std::fabs(a - b);
    const double rel = d / std::max(std::fabs(b), floor);
    if (rel > stats.max_rel) {
      stats.max_rel = rel;
      stats.worst = i;
    }
    stats.max_abs = std::max(stats.max_abs, d);
    diff_sq += d * d;
    ref_sq += b * b;
  }
  stats.rms_rel = ref_sq > 0 ? std::sqrt(diff_sq / ref_sq) : std::sqrt(diff_sq);
  return stats;
}

}  // namespace riner::test
