// training_step: the training step under each execution plan on the paper geometry (a shared
// DeepLesion slice, or the built-in phantom): steady-state wall time per step over a block of
// steps (the host enqueues ahead, as a real run does), device time per kernel, samples/s.
//   --plan=both|auto|cpu|gpu   --rays=160,640,...   --timed=N steps (default 300; tiny 10)
//   --scan=SINO (a scan with geometry.json beside it instead of the paper scene)
#include "cases/training_step.hpp"

#include <chrono>
#include <cmath>

#include "cl/context.hpp"
#include "cl/device_access.hpp"
#include "model/parameter_layout.hpp"
#include "riner/projector.hpp"
#include "riner/reconstructor.hpp"
#include "riner/scan.hpp"
#include "riner/simulate.hpp"
#include "scenes.hpp"

namespace riner::bench {

namespace {

// Arithmetic per sample of forward + backward (a multiply-add counts 2): encoding, the MLP
// forward, its backward (deltas and weight gradient: twice the forward), the grid gradient.
double step_flops_per_sample(const model::ParameterLayout& l) {
  const double corners = std::pow(2.0, l.dims);
  const double mlp =
      2.0 * (l.inputs * l.width + (l.hidden_layers - 1) * l.width * l.width + l.width);
  return l.levels * corners * (l.dims + 2.0 * l.features) + 3.0 * mlp +
         l.levels * corners * 2.0 * l.features;
}

}  // namespace

std::vector<Result> time_training_steps(const Device& device, const Options& o,
                                        const std::vector<std::string>& plans,
                                        const std::vector<int>& rays, const Peaks* peaks) {
  // --scan=SINO (geometry.json beside it) instead of the paper scene.
  RingScene scene;
  if (const std::string path = o.get("scan", ""); !path.empty()) {
    scene.sim.scan = load_scan(path);
    scene.name = path;
  } else {
    const Projector projector(preset_geometry("fan2d-paper"), Engine::kOpenCL, device);
    scene = paper_scene(o, o.get_int("slice", 0), projector);
  }
  const int timed = o.get_int("timed", o.size == "tiny" ? 10 : 300);
  std::vector<Result> out;
  for (const std::string& plan : plans) {
    for (int n_rays : rays) {
      RinerConfig config = config_from(o);
      if (!plan.empty()) config.plan.kind = plan;
      if (n_rays > 0) config.training.rays_per_step = n_rays;
      Reconstructor r(scene.sim.scan, config, device);
      r.step(o.size == "tiny" ? 2 : 50);  // past the program build and first allocations
      device.finish();
      const TrainingStats before = r.stats();
      riner::cl::context_of(device).set_recording(true);
      const auto start = std::chrono::steady_clock::now();
      r.step(timed);
      device.finish();
      const double wall_ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count() /
          timed;
      riner::cl::context_of(device).set_recording(false);
      std::map<std::string, double> kernel_ms;
      for (const cl::KernelTiming& k : riner::cl::context_of(device).take_timings())
        kernel_ms[k.kernel] += k.ms;
      const TrainingStats after = r.stats();
      const double samples = (after.samples - before.samples) / timed;
      const Geometry& g = scene.sim.scan.geometry;
      const model::ParameterLayout l =
          model::make_layout(2, r.config().encoding, config.network, g.n_u);
      const double gflops = samples * step_flops_per_sample(l) / (wall_ms * 1e6);
      const std::string plan_name = after.plan ? plan_kind_name(after.plan->kind) : "?";
      nlohmann::json f{{"scene", scene.name},
                       {"plan", after.plan ? after.plan->describe() : ""},
                       {"rays_per_step", r.config().training.rays_per_step},
                       {"samples_per_step", samples},
                       {"samples_kept_fraction", after.samples_kept_fraction},
                       {"wall_ms_per_step", wall_ms},
                       {"samples_per_second", samples / (wall_ms * 1e-3)},
                       {"gflops", gflops}};
      std::string line = format(
          "training_step %-4s %5d rays %7.0f samples  %8.3f ms/step  %9.3g samples/s  %6.1f "
          "GFLOP/s",
          plan_name.c_str(), r.config().training.rays_per_step, samples, wall_ms,
          samples / (wall_ms * 1e-3), gflops);
      if (peaks != nullptr) {
        const double peak =
            device.info().type == "CPU" ? peaks->host_gemm_gflops : peaks->device_gemm_gflops;
        f["fraction_of_gemm_peak"] = gflops / peak;
        line += format(" (%4.1f%% of GEMM peak)", 100.0 * gflops / peak);
      }
      for (const auto& [kernel, ms] : kernel_ms) {
        f["kernel_ms"][kernel] = ms / timed;
        line += format("\n    %-32s %8.4f ms/step", kernel.c_str(), ms / timed);
      }
      out.push_back({"training_step", f, line});
    }
  }
  return out;
}

namespace {

std::vector<Result> training_step(const Options& o) {
  const Device device = Device::open(o.device, true);
  const std::string plan = o.get("plan", "both");
  std::vector<std::string> plans{plan};
  if (plan == "both") plans = {"cpu", "gpu"};
  if (plan == "auto") plans = {""};
  return time_training_steps(device, o, plans, int_list(o.get("rays", "0")), nullptr);
}

}  // namespace

}  // namespace riner::bench

RINER_BENCH_CASE(training_step,
                 "the training step per execution plan: ms/step, samples/s, per-kernel time",
                 riner::bench::training_step);
