// The -D options that specialise the model kernels (hash_grid.cl, mlp.cl, riner_step.cl, ...)
// for one parameter layout, and the upload of its level table.
#pragma once

#include <string>

#include "cl/buffer.hpp"
#include "model/parameter_layout.hpp"
#include "riner/execution_plan.hpp"

namespace riner::ops {

// "-D DIMS=2 -D N_LEVELS=8 ..."; atomic adds -D ATOMIC_GRADIENTS and the float-atomic
// variant common.cl should use.
std::string model_build_options(const model::ParameterLayout& layout, bool atomic_gradients,
                                FloatAtomics atomics = FloatAtomics::kCompareExchange);

// The fastest float atomics of the context's device (its default execution plan's choice).
FloatAtomics device_float_atomics(const cl::Context& context);

cl::Buffer<model::GridLevel> upload_levels(cl::Context& context,
                                           const model::ParameterLayout& layout);

}  // namespace riner::ops
