// Random inputs for the cross-checks, reproducible from the printed test seed.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "support/fixture.hpp"

namespace riner::test {

// n floats uniform in [lo, hi); `salt` tells a test's inputs apart.
inline std::vector<float> uniform(std::size_t n, float lo, float hi, std::uint64_t salt) {
  std::mt19937_64 rng(seed() + salt);
  std::uniform_real_distribution<float> u(lo, hi);
  std::vector<float> v(n);
  for (float& x : v) x = u(rng);
  return v;
}

}  // namespace riner::test
