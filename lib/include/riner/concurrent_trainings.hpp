// Several trainings at once on one device: issue 30's throughput mode. One 256^2 slice leaves
// a GPU mostly idle (a step is a dozen short launches and a wait) and many CPU cores idle (a
// step's kernels have few work-groups, and a slab's reading, carving and ring corrections run
// on one host thread). Each worker thread holds its own context and in-order queue on the same
// device, so one training's launches and waits overlap another's work. Results do not depend
// on the number of workers: each job is trained alone, as it would be by itself.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>

#include "riner/device.hpp"

namespace riner {

struct Concurrency {
  int trainings = 1;
  std::string reason;  // a few words
};

// How many trainings fill this device (docs/history/RESULTS.md, "Issue 30: throughput"): on a GPU
// eight (an H200 trains 2.1x the slices per minute with 8 or 16 as with one), on a CPU one:
// PoCL shares one pool of threads among queues, so a second training in the same process
// gains little (1.1-1.3x on 2 cores) where separate processes of two cores each (MPI ranks,
// riner/slab_ranks.hpp) gain 5.5x on 16 cores.
Concurrency concurrent_trainings(const DeviceInfo& device);

// The most trainings this device's driver runs at once safely: 1 where several queues are
// known to fail (PoCL aborts now and then in pocl_release_dlhandle_cache: PoCL 5.0 at once,
// 3.1 once in about ten runs), else `wanted`. `why` (when given) says why it was cut.
int usable_trainings(const DeviceInfo& device, int wanted, std::string* why = nullptr);

// job(index, worker, device) for every index in [0, jobs), each index handed to whichever of
// `workers` threads is free (in order of index; cut by usable_trainings). Worker 0 runs on `device`
// itself, the others on their own queue on the same device (Device::sibling); with no device (the
// CPU reference engine) every worker gets none. The first exception stops the handing out; it is
// rethrown once every worker has finished its job.
using TrainingJob =
    std::function<void(std::size_t index, int worker, const std::optional<Device>&)>;
void run_concurrently(std::size_t jobs, int workers, const std::optional<Device>& device,
                      const TrainingJob& job);

}  // namespace riner
