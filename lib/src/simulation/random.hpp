// Random draws that are the same on every platform: std::mt19937_64's output sequence is fixed
// by the standard, but std::*_distribution algorithms are not, so riner uses its own.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

namespace riner::sim {

class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}

  // Uniform in [0, 1) with 53 random bits.
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }

  // Uniform integer in [0, n) without modulo bias (Lemire's rejection, 64-bit).
  std::uint64_t below(std::uint64_t n);

  // Poisson(mean): inversion for small means, Hormann's PTRS (transformed rejection with
  // squeeze, 1993) from mean 10 up.
  std::uint64_t poisson(double mean);

 private:
  std::mt19937_64 engine_;
};

}  // namespace riner::sim
