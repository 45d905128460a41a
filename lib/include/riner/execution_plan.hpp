// How the training step's work is shaped for one device: chosen in one place from the device's
// queried properties (type, compute units, local memory, float atomics), overridable from
// RinerConfig::plan, reported by `riner devices` and in summary.json.
//
// Both plans run the same step, sample-parallel (kernels/riner_step.cl): per-sample forward,
// one work-group for the ray sums and the loss, per-sample backward, the MLP's weight gradient
// as a split-K reduction (kernels/mlp_gradient.cl). They differ in how the hash grid's
// gradient is added up, and in how work is cut into work-groups:
//   cpu  the grid gradient reduced by ownership (kernels/hash_grid_gradient.cl: each
//        work-group owns a band of one level's table; deterministic, one gradient table);
//        work-groups sized so that every kernel has at least two per core (PoCL runs a
//        work-group on one thread).
//   gpu  the grid gradient added with the device's fastest float atomics (NVIDIA inline PTX,
//        cl_ext_float_atomics, AMD's builtin; a compare-and-swap loop as the last fallback);
//        thousands of work-items per launch.
#pragma once

#include <cstddef>
#include <string>

#include "riner/device.hpp"

namespace riner {

enum class PlanKind { kCpu, kGpu };

enum class FloatAtomics {
  kCompareExchange,  // OpenCL 1.2's atomic_cmpxchg on the bit pattern: portable, slow
  kNvidiaPtx,        // red.global.add.f32 in inline PTX
  kExtension,        // cl_ext_float_atomics (OpenCL C 3.0)
  kAmdBuiltin,       // __builtin_amdgcn_global_atomic_fadd_f32
};

// "auto" and 0 leave a choice to the device; anything else overrides it.
struct PlanConfig {
  std::string kind = "auto";           // auto, cpu, gpu
  std::string float_atomics = "auto";  // auto, nvidia-ptx, cl_ext_float_atomics, amd-builtin,
                                       // compare-exchange
  int sample_group = 0;                // work-group of the per-sample kernels, in samples
  int gradient_slices = 0;             // most work-groups of the MLP weight gradient
  int grid_bands = 0;                  // cpu plan: owners per encoding level
};

struct ExecutionPlan {
  PlanKind kind = PlanKind::kCpu;
  FloatAtomics float_atomics = FloatAtomics::kCompareExchange;  // gpu plan's grid gradient
  std::size_t sample_group = 64;
  std::size_t loss_group = 1;
  std::size_t gradient_slices = 4;
  std::size_t gradient_group = 64;
  std::size_t grid_bands = 1;
  // Rays per training step when the config leaves it to the plan (training.rays_per_step = 0):
  // a CPU is throughput-bound and gains nothing from bigger batches; a GPU runs small steps at
  // its launch latency, so 4x the rays cost 1.6x the time and buy 1.6 dB (docs/history/RESULTS.md).
  int rays_per_step = kCpuRaysPerStep;
  std::string reason;  // why these choices, in a few words

  static constexpr int kCpuRaysPerStep = 160;
  static constexpr int kGpuRaysPerStep = 640;

  std::string to_json() const;
  std::string describe() const;  // one line
};

// Throws InputError for an override the device cannot run (e.g. nvidia-ptx elsewhere).
ExecutionPlan choose_execution_plan(const DeviceInfo& device, const PlanConfig& config = {});

const char* plan_kind_name(PlanKind kind);
const char* float_atomics_name(FloatAtomics atomics);

}  // namespace riner
