// Counter-based random numbers: the same draws on the host and in kernels/common.cl, so the
// OpenCL and reference engines see identical batches, jitter and initial weights.
#pragma once

#include <cstdint>

namespace riner::model {

// A 32-bit integer hash with good avalanche (Chris Wellons' "lowbias32").
constexpr std::uint32_t hash32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352du;
  x ^= x >> 15;
  x *= 0x846ca68bu;
  x ^= x >> 16;
  return x;
}

// Hash of a tuple of keys.
constexpr std::uint32_t hash_keys(std::uint32_t a, std::uint32_t b, std::uint32_t c = 0,
                                  std::uint32_t d = 0) {
  return hash32(d ^ hash32(c ^ hash32(b ^ hash32(a))));
}

// Uniform in [0, 1) with 24 bits: exactly representable in float on both sides.
constexpr float uniform24(std::uint32_t h) {
  return static_cast<float>(h >> 8) * (1.0f / 16777216.0f);
}

// Streams keyed in hash_keys' first slot.
enum Stream : std::uint32_t {
  kInitStream = 1,
  kBatchStream = 2,
  kJitterStream = 3,
  kShuffleStream = 4
};

// Position k of a shuffled order of 0..n-1 keyed by `key` (a bijection on [0, n) for each key):
// a four-round Feistel network on the smallest even-bit power of two >= n, walking the cycle
// until it lands inside [0, n) (under 4 rounds of walking expected). Counter-based like the
// draws: no table, and any position of any key's order costs the same.
constexpr std::uint32_t shuffled_index(std::uint32_t k, std::uint32_t n, std::uint32_t key) {
  int half_bits = 1;
  while ((std::uint64_t{1} << (2 * half_bits)) < n) ++half_bits;
  const std::uint32_t mask = (std::uint32_t{1} << half_bits) - 1;
  std::uint32_t x = k;
  do {
    std::uint32_t left = x >> half_bits;
    std::uint32_t right = x & mask;
    for (std::uint32_t round = 0; round < 4; ++round) {
      const std::uint32_t next = left ^ (hash_keys(kShuffleStream, key, round, right) & mask);
      left = right;
      right = next;
    }
    x = (left << half_bits) | right;
  } while (x >= n);
  return x;
}

}  // namespace riner::model
