#include "riner/cores.hpp"

#include <sched.h>

#include <algorithm>
#include <cstdlib>
#include <string>
#include <thread>

namespace riner {

unsigned machine_cores() { return std::max(1u, std::thread::hardware_concurrency()); }

unsigned usable_cores() {
  cpu_set_t mask;
  CPU_ZERO(&mask);
  if (sched_getaffinity(0, sizeof(mask), &mask) != 0) return machine_cores();
  const int count = CPU_COUNT(&mask);
  return count > 0 ? static_cast<unsigned>(count) : machine_cores();
}

std::vector<int> usable_core_ids() {
  cpu_set_t mask;
  CPU_ZERO(&mask);
  std::vector<int> ids;
  if (sched_getaffinity(0, sizeof(mask), &mask) != 0) return ids;
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (CPU_ISSET(c, &mask)) ids.push_back(c);
  }
  return ids;
}

std::vector<std::vector<int>> core_groups(const std::vector<int>& cores, int count, int per_group) {
  std::vector<std::vector<int>> groups;
  if (count < 2 || per_group < 1 ||
      static_cast<std::size_t>(count) * static_cast<std::size_t>(per_group) > cores.size()) {
    return groups;
  }
  for (int g = 0; g < count; ++g) {
    const auto first = cores.begin() + static_cast<std::ptrdiff_t>(g) * per_group;
    groups.emplace_back(first, first + per_group);
  }
  return groups;
}

void fit_opencl_threads_to_usable_cores() {
  const auto chosen = [](const char* name) {
    const char* value = std::getenv(name);
    return value != nullptr && *value != '\0';
  };
  // PoCL reads POCL_MAX_PTHREAD_COUNT first (3.1 only that), newer ones then these two.
  if (chosen("POCL_MAX_PTHREAD_COUNT") || chosen("POCL_CPU_MAX_CU_COUNT") ||
      chosen("POCL_MAX_COMPUTE_UNITS")) {
    return;
  }
  const unsigned usable = usable_cores();
  if (usable >= machine_cores()) return;
  setenv("POCL_MAX_PTHREAD_COUNT", std::to_string(usable).c_str(), 0);
}

}  // namespace riner
