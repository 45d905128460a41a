// Splitting CPU work over the machine's cores with fixed, contiguous chunks, so results do not
// depend on scheduling. RINER_THREADS caps the thread count.
#pragma once

#include <algorithm>
#include <cstddef>
#include <functional>
#include <vector>

namespace riner::util {

std::size_t worker_count();

// Number of chunks [0, n) is split into (at most one per worker, at least 1).
std::size_t chunk_count(std::size_t n);

// fn(chunk, begin, end) for every chunk, in parallel; rethrows the first exception.
void parallel_chunks(std::size_t n,
                     const std::function<void(std::size_t, std::size_t, std::size_t)>& fn);

// fn(begin, end) over contiguous chunks of [0, n).
inline void parallel_for(std::size_t n, const std::function<void(std::size_t, std::size_t)>& fn) {
  parallel_chunks(n, [&](std::size_t, std::size_t begin, std::size_t end) { fn(begin, end); });
}

// The results of fn(begin, end) per chunk, in chunk order.
template <typename Fn>
auto parallel_map_chunks(std::size_t n, Fn&& fn)
    -> std::vector<decltype(fn(std::size_t{}, std::size_t{}))> {
  std::vector<decltype(fn(std::size_t{}, std::size_t{}))> results(chunk_count(n));
  parallel_chunks(n, [&](std::size_t chunk, std::size_t begin, std::size_t end) {
    results[chunk] = fn(begin, end);
  });
  return results;
}

}  // namespace riner::util
