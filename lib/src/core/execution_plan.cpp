#include "riner/execution_plan.hpp"

#include <algorithm>
#include <cctype>
#include <nlohmann/json.hpp>

#include "riner/error.hpp"

namespace riner {

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

bool is_nvidia(const DeviceInfo& d) {
  return lower(d.platform).find("nvidia") != std::string::npos ||
         lower(d.vendor).find("nvidia") != std::string::npos;
}

bool is_amd(const DeviceInfo& d) {
  const std::string v = lower(d.vendor);
  return d.type == "GPU" && (v.find("advanced micro devices") != std::string::npos ||
                             lower(d.platform).find("amd") != std::string::npos);
}

FloatAtomics parse_atomics(const std::string& name) {
  if (name == "nvidia-ptx") return FloatAtomics::kNvidiaPtx;
  if (name == "cl_ext_float_atomics") return FloatAtomics::kExtension;
  if (name == "amd-builtin") return FloatAtomics::kAmdBuiltin;
  if (name == "compare-exchange") return FloatAtomics::kCompareExchange;
  throw InputError(
      "plan.float_atomics must be auto, nvidia-ptx, cl_ext_float_atomics, "
      "amd-builtin or compare-exchange (got " +
      name + ")");
}

// The device's fastest float add for accumulation. A CPU reporting cl_ext_float_atomics (PoCL
// 5) does not declare the builtins in its compiler: compare-and-swap there.
FloatAtomics best_atomics(const DeviceInfo& d) {
  if (is_nvidia(d)) return FloatAtomics::kNvidiaPtx;
  if (d.fp32_global_atomic_add && d.type != "CPU") return FloatAtomics::kExtension;
  if (is_amd(d)) return FloatAtomics::kAmdBuiltin;
  return FloatAtomics::kCompareExchange;
}

}  // namespace

const char* plan_kind_name(PlanKind kind) { return kind == PlanKind::kCpu ? "cpu" : "gpu"; }

const char* float_atomics_name(FloatAtomics atomics) {
  switch (atomics) {
    case FloatAtomics::kCompareExchange:
      return "compare-exchange";
    case FloatAtomics::kNvidiaPtx:
      return "nvidia-ptx";
    case FloatAtomics::kExtension:
      return "cl_ext_float_atomics";
    case FloatAtomics::kAmdBuiltin:
      return "amd-builtin";
  }
  return "unknown";
}

ExecutionPlan choose_execution_plan(const DeviceInfo& d, const PlanConfig& c) {
  ExecutionPlan plan;
  if (c.kind == "auto") {
    plan.kind = d.type == "CPU" ? PlanKind::kCpu : PlanKind::kGpu;
    plan.reason = d.type == "CPU" ? "a CPU device" : "a " + d.type + " device";
  } else if (c.kind == "cpu" || c.kind == "gpu") {
    plan.kind = c.kind == "cpu" ? PlanKind::kCpu : PlanKind::kGpu;
    plan.reason = "plan.kind = " + c.kind;
  } else {
    throw InputError("plan.kind must be auto, cpu or gpu (got " + c.kind + ")");
  }
  const std::size_t units = std::max<std::uint32_t>(1, d.compute_units);
  const std::size_t max_group = std::max<std::size_t>(1, d.max_work_group_size);
  if (plan.kind == PlanKind::kCpu) {
    // PoCL runs a work-group on one thread: two or more per core, each with real work. 128
    // samples a group (8 work-items of the lanes kernels): a step's ~10^4 samples make ~90
    // groups, where 64 work-items of 16 made 11, unevenly shared by 2 threads.
    plan.sample_group = 128;
    plan.loss_group = 1;
    plan.gradient_slices = 2 * units;
    plan.gradient_group = 64;
    // One owner per level: more bands mean every owner scans every sample again, which cost
    // more than it parallelised on 16 cores (docs/history/RESULTS.md).
    plan.grid_bands = 1;
    plan.float_atomics = FloatAtomics::kCompareExchange;  // not used: the grid is owned
  } else {
    plan.sample_group = 128;
    plan.loss_group = 256;
    plan.gradient_slices = 2 * units;
    plan.gradient_group = 128;
    plan.grid_bands = 1;
    plan.rays_per_step = ExecutionPlan::kGpuRaysPerStep;
    plan.float_atomics = best_atomics(d);
  }
  if (c.float_atomics != "auto") {
    plan.float_atomics = parse_atomics(c.float_atomics);
    if (plan.float_atomics == FloatAtomics::kNvidiaPtx && !is_nvidia(d))
      throw InputError("plan.float_atomics = nvidia-ptx needs an NVIDIA device");
    if (plan.float_atomics == FloatAtomics::kExtension && !d.fp32_global_atomic_add)
      throw InputError(
          "plan.float_atomics = cl_ext_float_atomics: the device does not report "
          "global float atomic add");
  }
  if (c.sample_group > 0) plan.sample_group = static_cast<std::size_t>(c.sample_group);
  if (c.gradient_slices > 0) plan.gradient_slices = static_cast<std::size_t>(c.gradient_slices);
  if (c.grid_bands > 0) plan.grid_bands = static_cast<std::size_t>(c.grid_bands);
  for (std::size_t* size : {&plan.sample_group, &plan.loss_group, &plan.gradient_group}) {
    *size = std::min(*size, max_group);
  }
  if (c.sample_group > 0 && static_cast<std::size_t>(c.sample_group) > max_group) {
    throw InputError("plan.sample_group " + std::to_string(c.sample_group) +
                     " exceeds the device's largest work-group (" + std::to_string(max_group) +
                     ")");
  }
  return plan;
}

std::string ExecutionPlan::to_json() const {
  return nlohmann::json{{"kind", plan_kind_name(kind)},
                        {"grid_gradient", kind == PlanKind::kCpu ? "owned bands" : "atomics"},
                        {"float_atomics", float_atomics_name(float_atomics)},
                        {"sample_group", sample_group},
                        {"loss_group", loss_group},
                        {"gradient_slices", gradient_slices},
                        {"gradient_group", gradient_group},
                        {"grid_bands", grid_bands},
                        {"rays_per_step", rays_per_step},
                        {"reason", reason}}
      .dump();
}

std::string ExecutionPlan::describe() const {
  std::string s = std::string(plan_kind_name(kind)) + " plan: " + std::to_string(rays_per_step) +
                  " rays per step, work-groups of " + std::to_string(sample_group) +
                  " per sample, MLP gradient in up to " + std::to_string(gradient_slices) +
                  " slices, ";
  if (kind == PlanKind::kCpu) {
    s += "grid gradient by " + std::to_string(grid_bands) + " owner(s) per level";
  } else {
    s += std::string("grid gradient by ") + float_atomics_name(float_atomics) + " atomics";
  }
  return s + " (" + reason + ")";
}

}  // namespace riner
