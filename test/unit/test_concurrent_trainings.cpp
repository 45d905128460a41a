// Several trainings at once: every job runs exactly once whatever the workers, the first error
// stops the handing out and reaches the caller, and drivers known to fail with several queues
// get one at a time.
#include <doctest/doctest.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

#include "riner/concurrent_trainings.hpp"

TEST_SUITE("unit") {
  TEST_CASE("run_concurrently runs every job once, on at most the workers asked") {
    for (int workers : {1, 2, 5, 40}) {
      CAPTURE(workers);
      std::vector<int> runs(17, 0);
      std::set<int> seen_workers;
      std::mutex mutex;
      riner::run_concurrently(
          runs.size(), workers, std::nullopt,
          [&](std::size_t i, int worker, const std::optional<riner::Device>& d) {
            std::lock_guard<std::mutex> lock(mutex);
            CHECK(!d.has_value());
            ++runs[i];
            seen_workers.insert(worker);
          });
      for (int n : runs) CHECK(n == 1);
      CHECK(static_cast<int>(seen_workers.size()) <= std::min(workers, 17));
      CHECK(*seen_workers.begin() >= 0);
      CHECK(*seen_workers.rbegin() < std::min(workers, 17));
    }
    int calls = 0;
    riner::run_concurrently(
        0, 4, std::nullopt,
        [&](std::size_t, int, const std::optional<riner::Device>&) { ++calls; });
    CHECK(calls == 0);
  }

  TEST_CASE("run_concurrently rethrows the first error and stops handing out jobs") {
    std::atomic<int> started{0};
    CHECK_THROWS_WITH_AS(
        riner::run_concurrently(1000, 3, std::nullopt,
                                [&](std::size_t i, int, const std::optional<riner::Device>&) {
                                  ++started;
                                  if (i == 4) throw std::runtime_error("job 4 failed");
                                  // A training takes a while: the error is caught long before.
                                  std::this_thread::sleep_for(std::chrono::milliseconds(5));
                                }),
        "job 4 failed", std::runtime_error);
    // The three workers finish the jobs in hand; nobody takes the remaining hundreds.
    CHECK(started.load() < 20);
  }

  TEST_CASE("usable_trainings: one at a time where several queues are known to fail") {
    riner::DeviceInfo pocl;
    pocl.platform = "Portable Computing Language";
    pocl.type = "CPU";
    pocl.driver_version = "5.0+debian";
    std::string why;
    CHECK(riner::usable_trainings(pocl, 8, &why) == 1);
    CHECK(why.find("PoCL 5.0+debian can abort") != std::string::npos);
    pocl.driver_version = "3.1+debian";
    CHECK(riner::usable_trainings(pocl, 8) == 1);
    riner::DeviceInfo other_cpu;
    other_cpu.platform = "Intel(R) OpenCL";
    other_cpu.type = "CPU";
    CHECK(riner::usable_trainings(other_cpu, 4) == 4);
    riner::DeviceInfo gpu;
    gpu.platform = "NVIDIA CUDA";
    gpu.type = "GPU";
    CHECK(riner::usable_trainings(gpu, 16) == 16);
    CHECK(riner::usable_trainings(gpu, 0) == 1);
    CHECK(riner::concurrent_trainings(gpu).trainings == 8);
    CHECK(riner::concurrent_trainings(pocl).trainings == 1);
  }
}
