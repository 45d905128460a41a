#include "op_timer.hpp"

#include "cl/context.hpp"
#include "cl/device_access.hpp"

namespace riner::bench {

nlohmann::json OpTiming::to_json() const {
  nlohmann::json kernels = nlohmann::json::object();
  for (const auto& [name, s] : kernel_ms) kernels[name] = s.median;
  return {{"wall_ms", wall_ms.to_json()},
          {"device_ms", device_ms.to_json()},
          {"kernel_median_ms", kernels}};
}

OpTiming time_op(const Device& device, int warmup, int runs, const std::function<void()>& op) {
  cl::Context& ctx = riner::cl::context_of(device);
  for (int i = 0; i < warmup; ++i) op();
  ctx.finish();
  std::vector<double> wall, total;
  std::map<std::string, std::vector<double>> per_kernel;
  for (int i = 0; i < std::max(runs, 1); ++i) {
    ctx.set_recording(device.profiling());
    wall.push_back(time_ms([&] {
      op();
      ctx.finish();
    }));
    ctx.set_recording(false);
    std::map<std::string, double> sums;
    double sum = 0.0;
    for (const cl::KernelTiming& t : ctx.take_timings()) {
      sums[t.kernel] += t.ms;
      sum += t.ms;
    }
    total.push_back(sum);
    for (const auto& [name, ms] : sums) per_kernel[name].push_back(ms);
  }
  OpTiming out;
  out.wall_ms = Stats::of(wall);
  out.device_ms = Stats::of(total);
  for (auto& [name, samples] : per_kernel) out.kernel_ms[name] = Stats::of(samples);
  return out;
}

}  // namespace riner::bench
