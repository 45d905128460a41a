#include "ops/mlp.hpp"

#include "ops/model_program.hpp"
#include "riner/error.hpp"

namespace riner::ops {

MlpOp::MlpOp(cl::Context& context, const model::ParameterLayout& layout)
    : context_(context),
      layout_(layout),
      program_(context.program({"common", "mlp"},
                               model_build_options(layout, true, device_float_atomics(context)))),
      forward_(*program_, "mlp_forward_batch"),
      backward_(*program_, "mlp_backward_batch") {}

void MlpOp::forward(const cl::Buffer<float>& params, const cl::Buffer<float>& inputs,
                    cl::Buffer<float>& outputs) {
  const auto n = static_cast<cl_uint>(outputs.size());
  if (inputs.size() != n * static_cast<std::size_t>(layout_.inputs) ||
      params.size() != layout_.total) {
    throw Error("mlp_forward: buffer sizes do not match the layout");
  }
  forward_.set_args(n, params, static_cast<cl_uint>(layout_.mlp_offset), inputs, outputs);
  context_.launch(forward_, n);
}

void MlpOp::backward(const cl::Buffer<float>& params, const cl::Buffer<float>& inputs,
                     const cl::Buffer<float>& d_outputs, cl::Buffer<float>& grad,
                     cl::Buffer<float>& d_inputs) {
  const auto n = static_cast<cl_uint>(d_outputs.size());
  if (inputs.size() != n * static_cast<std::size_t>(layout_.inputs) ||
      d_inputs.size() != inputs.size() || params.size() != layout_.total ||
      grad.size() != layout_.total) {
    throw Error("mlp_backward: buffer sizes do not match the layout");
  }
  backward_.set_args(n, params, static_cast<cl_uint>(layout_.mlp_offset), inputs, d_outputs, grad,
                     d_inputs);
  context_.launch(backward_, n);
}

}  // namespace riner::ops
