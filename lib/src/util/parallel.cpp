#include "util/parallel.hpp"

#include <cstdlib>
#include <exception>
#include <mutex>
#include <thread>

#include "riner/cores.hpp"

namespace riner::util {

std::size_t worker_count() {
  static const std::size_t count = [] {
    std::size_t n = usable_cores();
    if (const char* env = std::getenv("RINER_THREADS"); env != nullptr && *env != '\0') {
      n = static_cast<std::size_t>(std::max(1L, std::strtol(env, nullptr, 10)));
    }
    return n;
  }();
  return count;
}

std::size_t chunk_count(std::size_t n) {
  return std::max<std::size_t>(1, std::min(worker_count(), n));
}

void parallel_chunks(std::size_t n,
                     const std::function<void(std::size_t, std::size_t, std::size_t)>& fn) {
  const std::size_t chunks = chunk_count(n);
  if (chunks == 1) {
    fn(0, 0, n);
    return;
  }
  std::exception_ptr error;
  std::mutex mutex;
  std::vector<std::thread> threads;
  for (std::size_t c = 0; c < chunks; ++c) {
    threads.emplace_back([&, c] {
      try {
        fn(c, n * c / chunks, n * (c + 1) / chunks);
      } catch (...) {
        std::lock_guard<std::mutex> lock(mutex);
        if (!error) error = std::current_exception();
      }
    });
  }
  for (auto& t : threads) t.join();
  if (error) std::rethrow_exception(error);
}

}  // namespace riner::util
