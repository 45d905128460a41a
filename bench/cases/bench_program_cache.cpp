// Program build time with an empty cache vs a second process that finds the binary on disk.
// PoCL keeps its own kernel cache; it is switched off (POCL_KERNEL_CACHE=0) so the first
// number is a real compile.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>

#include "cl/context.hpp"
#include "cl/device_access.hpp"
#include "harness.hpp"
#include "riner/device.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

// Child mode: build every program once in this process and print "ms source|disk".
std::vector<Result> build_once(const Options& options) {
  riner::Device device = riner::Device::open(options.device);
  const double ms = riner::bench::time_ms([&] {
    riner::cl::context_of(device).program({"common", "vector_ops"});
  });
  const auto stats = riner::cl::context_of(device).program_cache_stats();
  std::printf("BUILD %.3f %s\n", ms, stats.disk_hits > 0 ? "disk" : "source");
  return {};
}

double run_child(const Options& options, const std::filesystem::path& cache, bool* from_disk) {
  const std::string command = "RINER_CACHE_DIR='" + cache.string() + "' POCL_KERNEL_CACHE=0 '" +
                              options.self + "' --case=program_build_once --device='" +
                              options.device + "'";
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) throw std::runtime_error("cannot start " + command);
  double ms = -1;
  char line[256];
  while (std::fgets(line, sizeof(line), pipe) != nullptr) {
    char kind[16] = {0};
    if (std::sscanf(line, "BUILD %lf %15s", &ms, kind) == 2)
      *from_disk = std::string(kind) == "disk";
  }
  if (pclose(pipe) != 0 || ms < 0) throw std::runtime_error("child build failed: " + command);
  return ms;
}

std::vector<Result> program_cache(const Options& options) {
  std::vector<double> cold;
  std::vector<double> warm;
  for (int run = 0; run < std::max(1, options.runs); ++run) {
    const auto cache = std::filesystem::temp_directory_path() /
                       ("riner_bench_cache_" + std::to_string(std::random_device{}()));
    bool disk = false;
    cold.push_back(run_child(options, cache, &disk));
    if (disk) throw std::runtime_error("first build claimed a cache hit");
    warm.push_back(run_child(options, cache, &disk));
    if (!disk) throw std::runtime_error("second process did not hit the cache");
    std::filesystem::remove_all(cache);
  }
  const auto c = riner::bench::Stats::of(cold);
  const auto w = riner::bench::Stats::of(warm);
  return {{"program_cache",
           {{"program", "common+vector_ops"},
            {"first_process_ms_median", c.median},
            {"first_process_ms_min", c.min},
            {"second_process_ms_median", w.median},
            {"second_process_ms_min", w.min},
            {"speedup_median", c.median / w.median},
            {"runs", cold.size()}}}};
}

}  // namespace

RINER_BENCH_CASE(program_build_once, "(internal) build programs once, report source/disk",
                 build_once);
RINER_BENCH_CASE(program_cache, "program build: empty cache vs a second process", program_cache);
