#include "riner/concurrent_trainings.hpp"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "riner/error.hpp"

namespace riner {

namespace {

// Trainings at once on a GPU: an H200 gains 1.8x with 4, 2.1x with 8 or 16
// (docs/history/RESULTS.md).
constexpr int kGpuTrainings = 8;

}  // namespace

Concurrency concurrent_trainings(const DeviceInfo& device) {
  if (device.type == "GPU") {
    return {kGpuTrainings, "a GPU step is launch-bound: " + std::to_string(kGpuTrainings) +
                               " trainings overlap their launches"};
  }
  if (device.type == "CPU") {
    return {1, "a CPU's cores are filled by processes (mpirun -n), not by queues"};
  }
  return {1, "one training on a " + device.type + " device"};
}

int usable_trainings(const DeviceInfo& device, int wanted, std::string* why) {
  if (wanted <= 1) return 1;
  if (device.platform.find("Portable Computing Language") != std::string::npos) {
    if (why) {
      *why = "PoCL " + device.driver_version +
             " can abort with several training queues at once (in its kernel cache): one at a "
             "time (on a CPU, run several processes: mpirun -n N)";
    }
    return 1;
  }
  return wanted;
}

void run_concurrently(std::size_t jobs, int workers, const std::optional<Device>& device,
                      const TrainingJob& job) {
  if (!job) throw Error("run_concurrently: no job given");
  if (device) workers = usable_trainings(device->info(), workers);
  const int n =
      static_cast<int>(std::min<std::size_t>(std::max(1, workers), std::max<std::size_t>(jobs, 1)));
  std::atomic<std::size_t> next{0};
  std::atomic<bool> failed{false};
  std::exception_ptr error;
  std::mutex error_mutex;
  auto work = [&](int worker, const std::optional<Device>& own) {
    try {
      for (std::size_t i = next++; i < jobs && !failed; i = next++) job(i, worker, own);
    } catch (...) {
      std::lock_guard<std::mutex> lock(error_mutex);
      if (!error) error = std::current_exception();
      failed = true;
    }
  };
  if (n == 1) {
    work(0, device);
  } else {
    std::vector<std::optional<Device>> devices(static_cast<std::size_t>(n));
    devices[0] = device;
    for (int w = 1; w < n; ++w) {
      if (device) devices[static_cast<std::size_t>(w)] = device->sibling();
    }
    std::vector<std::thread> threads;
    for (int w = 1; w < n; ++w)
      threads.emplace_back(work, w, std::cref(devices[static_cast<std::size_t>(w)]));
    work(0, devices[0]);
    for (std::thread& t : threads) t.join();
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace riner
