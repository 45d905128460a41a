// FNV-1a 64-bit: a fast, stable hash for cache keys and checksums (not for security).
#pragma once

#include <cstdint>
#include <string_view>

namespace riner::util {

constexpr std::uint64_t kFnvOffset = 14695981039346656037ull;

inline std::uint64_t fnv1a64(std::string_view bytes, std::uint64_t hash = kFnvOffset) {
  for (unsigned char c : bytes) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  return hash;
}

}  // namespace riner::util
