#include "ops/model_program.hpp"

namespace riner::ops {

std::string model_build_options(const model::ParameterLayout& l, bool atomic_gradients) {
  std::string o = "-D DIMS=" + std::to_string(l.dims) + " -D N_LEVELS=" + std::to_string(l.levels) +
                  " -D N_FEATURES=" + std::to_string(l.features) +
                  " -D TABLE_SIZE=" + std::to_string(l.table_size) +
                  "u -D MLP_INPUTS=" + std::to_string(l.inputs) +
                  " -D MLP_WIDTH=" + std::to_string(l.width) +
                  " -D MLP_HIDDEN=" + std::to_string(l.hidden_layers);
  if (atomic_gradients) o += " -D ATOMIC_GRADIENTS";
  return o;
}

cl::Buffer<model::GridLevel> upload_levels(cl::Context& context, const model::ParameterLayout& l) {
  return cl::Buffer<model::GridLevel>(context, std::span<const model::GridLevel>(l.grid),
                                      CL_MEM_READ_ONLY);
}

}  // namespace riner::ops
