#include "ops/model_program.hpp"

namespace riner::ops {

std::string model_build_options(const model::ParameterLayout& l, bool atomic_gradients,
                                FloatAtomics atomics) {
  std::string o = "-D DIMS=" + std::to_string(l.dims) + " -D N_LEVELS=" + std::to_string(l.levels) +
                  " -D N_FEATURES=" + std::to_string(l.features) +
                  " -D TABLE_SIZE=" + std::to_string(l.table_size) +
                  "u -D MLP_INPUTS=" + std::to_string(l.inputs) +
                  " -D MLP_WIDTH=" + std::to_string(l.width) +
                  " -D MLP_HIDDEN=" + std::to_string(l.hidden_layers);
  if (!atomic_gradients) return o;
  o += " -D ATOMIC_GRADIENTS";
  switch (atomics) {
    case FloatAtomics::kNvidiaPtx:
      return o + " -D FLOAT_ATOMICS_NV";
    case FloatAtomics::kExtension:
      return o + " -D FLOAT_ATOMICS_EXT -cl-std=CL3.0";
    case FloatAtomics::kAmdBuiltin:
      return o + " -D FLOAT_ATOMICS_AMD";
    case FloatAtomics::kCompareExchange:
      break;
  }
  return o;
}

FloatAtomics device_float_atomics(const cl::Context& context) {
  PlanConfig gpu;
  gpu.kind = "gpu";
  return choose_execution_plan(context.info(), gpu).float_atomics;
}

cl::Buffer<model::GridLevel> upload_levels(cl::Context& context, const model::ParameterLayout& l) {
  return cl::Buffer<model::GridLevel>(context, std::span<const model::GridLevel>(l.grid),
                                      CL_MEM_READ_ONLY);
}

}  // namespace riner::ops
