// The sums a centre finder keeps over the reading pairs it compares (a reading and its mirror
// or conjugate): their mean squared difference, and that difference relative to the spread of
// the readings compared (both sides about their means). Relative, noise meeting noise (air)
// scores about 1 and a true axis with object in the pairs near 0, so axes with few pairs (a half
// acquisition's, near one end of the detector) compare fairly with axes with many.
#pragma once

#include <cstddef>
#include <limits>

namespace riner::preprocessing {

struct MismatchSums {
  double squared = 0.0;
  double sum_a = 0.0, sum_aa = 0.0, sum_b = 0.0, sum_bb = 0.0;
  std::size_t pairs = 0;

  void add(double a, double b) {
    squared += (a - b) * (a - b);
    sum_a += a;
    sum_aa += a * a;
    sum_b += b;
    sum_bb += b * b;
    ++pairs;
  }
  // Mean squared difference; infinity without a pair.
  double mean() const {
    return pairs ? squared / static_cast<double>(pairs) : std::numeric_limits<double>::infinity();
  }
  // The squared difference over the spread; infinity under two pairs or without spread.
  double relative() const {
    if (pairs < 2) return std::numeric_limits<double>::infinity();
    const auto n = static_cast<double>(pairs);
    const double spread = sum_aa - sum_a * sum_a / n + sum_bb - sum_b * sum_b / n;
    return spread > 0.0 ? squared / spread : std::numeric_limits<double>::infinity();
  }
};

}  // namespace riner::preprocessing
