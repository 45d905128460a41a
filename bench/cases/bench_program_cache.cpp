// A program's build and first launch in a first process (riner's cache and PoCL's own kernel
// cache both empty) vs a second process (both as the first left them). riner's cache serves
// drivers other than PoCL (cl/program_builder.hpp); on PoCL the second process is served by
// PoCL's cache alone.
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <random>

#include "cl/buffer.hpp"
#include "cl/context.hpp"
#include "cl/device_access.hpp"
#include "cl/program_builder.hpp"
#include "harness.hpp"
#include "ops/vector_ops.hpp"
#include "riner/device.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

// Child mode: build the program and launch its kernels once in this process (PoCL compiles a
// kernel at its first launch); print "ms source|disk".
std::vector<Result> build_once(const Options& options) {
  riner::Device device = riner::Device::open(options.device);
  riner::cl::Context& context = riner::cl::context_of(device);
  const double ms = riner::bench::time_ms([&] {
    riner::ops::VectorOps ops(context);
    riner::cl::Buffer<float> x(context, 1000), y(context, 1000), total(context, 1);
    ops.fill(x, 1.0f);
    ops.fill(y, 2.0f);
    ops.axpy(0.5f, x, y);
    ops.sum(y, total);
    context.finish();
  });
  const auto stats = riner::cl::context_of(device).program_cache_stats();
  std::printf("BUILD %.3f %s\n", ms, stats.disk_hits > 0 ? "disk" : "source");
  return {};
}

double run_child(const Options& options, const std::filesystem::path& cache, bool* from_disk) {
  const std::string command = "RINER_CACHE_DIR='" + cache.string() + "' POCL_CACHE_DIR='" +
                              (cache / "pocl").string() + "' '" + options.self +
                              "' --case=program_build_once --device='" + options.device + "'";
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
  riner::Device device = riner::Device::open(options.device);
  const bool served = riner::cl::disk_cache_serves(riner::cl::context_of(device).info().platform);
  std::vector<double> cold;
  std::vector<double> warm;
  for (int run = 0; run < std::max(1, options.runs); ++run) {
    const auto cache = std::filesystem::temp_directory_path() /
                       ("riner_bench_cache_" + std::to_string(std::random_device{}()));
    bool disk = false;
    cold.push_back(run_child(options, cache, &disk));
    if (disk) throw std::runtime_error("first build claimed a cache hit");
    warm.push_back(run_child(options, cache, &disk));
    if (disk != served) {
      throw std::runtime_error(served ? "second process did not hit riner's cache"
                                      : "riner's cache served PoCL, which it should leave alone");
    }
    std::filesystem::remove_all(cache);
  }
  const auto c = riner::bench::Stats::of(cold);
  const auto w = riner::bench::Stats::of(warm);
  return {{"program_cache",
           {{"program", "common+vector_ops, built and launched"},
            {"riner_cache", served},
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
