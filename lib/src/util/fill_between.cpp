#include "util/fill_between.hpp"

#include <cmath>

namespace riner::util {

namespace {

// Line `to` = the blend of lines `a` and `b` (weight w on b) of n values, the finite one alone
// where the other is not.
void blend_line(float* to, const float* a, const float* b, float w, std::size_t n) {
  for (std::size_t k = 0; k < n; ++k) {
    const bool has_a = std::isfinite(a[k]), has_b = std::isfinite(b[k]);
    if (has_a && has_b) {
      to[k] = (1.0f - w) * a[k] + w * b[k];
    } else if (has_a) {
      to[k] = a[k];
    } else if (has_b) {
      to[k] = b[k];
    }
  }
}

}  // namespace

bool fill_between(float* base, std::size_t stride, std::size_t size, std::vector<bool>& empty) {
  const std::size_t count = empty.size();
  long previous = -1;
  bool any = false;
  for (std::size_t j = 0; j <= count; ++j) {
    if (j < count && empty[j]) continue;
    if (j < count) any = true;
    for (std::size_t k = static_cast<std::size_t>(previous + 1); k < j; ++k) {
      if (previous < 0 && j == count) break;
      const std::size_t a = previous >= 0 ? static_cast<std::size_t>(previous) : j;
      const std::size_t b = j < count ? j : a;
      const float w = a == b ? 0.0f : static_cast<float>(k - a) / static_cast<float>(b - a);
      blend_line(base + k * stride, base + a * stride, base + b * stride, w, size);
      empty[k] = false;
    }
    previous = static_cast<long>(j);
  }
  return any;
}

}  // namespace riner::util
