// Times an operation on a device: warm-up runs, then repeated runs, each finished on the queue,
// with wall time and the device time of every kernel launched (OpenCL profiling events).
#pragma once

#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "harness.hpp"
#include "riner/device.hpp"

namespace riner::bench {

struct OpTiming {
  Stats wall_ms;                           // per run, host wall clock until the queue is done
  Stats device_ms;                         // per run, sum of the kernels' device times
  std::map<std::string, Stats> kernel_ms;  // per run, per kernel name (summed over launches)
  nlohmann::json to_json() const;
};

// `device` must have been opened with profiling on for device times (else they read 0).
OpTiming time_op(const Device& device, int warmup, int runs, const std::function<void()>& op);

}  // namespace riner::bench
