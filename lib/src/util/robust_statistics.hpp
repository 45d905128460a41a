// Robust statistics shared by the evidence read off a measurement and the quality report.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace riner::util {

// Median absolute deviation to the standard deviation of a normal distribution.
constexpr double kMadToSigma = 1.4826;

// The value of rank q (n - 1), 0 <= q <= 1, of non-empty `values` (which it reorders).
inline double quantile(std::vector<double>& values, double q) {
  const auto k = static_cast<std::ptrdiff_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return values[static_cast<std::size_t>(k)];
}

}  // namespace riner::util
