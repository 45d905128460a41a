#include "ops/hash_grid.hpp"

#include "ops/model_program.hpp"
#include "riner/error.hpp"

namespace riner::ops {

HashGridOp::HashGridOp(cl::Context& context, const model::ParameterLayout& layout)
    : context_(context),
      layout_(layout),
      levels_(upload_levels(context, layout)),
      program_(context.program({"common", "hash_grid"},
                               model_build_options(layout, true, device_float_atomics(context)))),
      forward_(*program_, "hash_grid_forward"),
      backward_(*program_, "hash_grid_backward") {}

void HashGridOp::forward(const cl::Buffer<float>& params, const cl::Buffer<float>& positions,
                         cl::Buffer<float>& features) {
  const auto n = static_cast<cl_uint>(positions.size() / layout_.dims);
  if (features.size() != n * static_cast<std::size_t>(layout_.inputs) ||
      params.size() < layout_.grid_params) {
    throw Error("hash_grid_forward: buffer sizes do not match the layout");
  }
  forward_.set_args(n, levels_, params, positions, features);
  context_.launch(forward_, n);
}

void HashGridOp::backward(const cl::Buffer<float>& positions, const cl::Buffer<float>& d_features,
                          cl::Buffer<float>& grad) {
  const auto n = static_cast<cl_uint>(positions.size() / layout_.dims);
  if (d_features.size() != n * static_cast<std::size_t>(layout_.inputs) ||
      grad.size() < layout_.grid_params) {
    throw Error("hash_grid_backward: buffer sizes do not match the layout");
  }
  backward_.set_args(n, levels_, positions, d_features, grad);
  context_.launch(backward_, n);
}

}  // namespace riner::ops
