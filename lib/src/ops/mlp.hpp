// Host side of kernels/mlp.cl: the MLP on explicit batches of inputs (forward, and backward
// with atomic weight-gradient accumulation).
#pragma once

#include <memory>

#include "cl/buffer.hpp"
#include "cl/program.hpp"
#include "model/parameter_layout.hpp"

namespace riner::ops {

class MlpOp {
 public:
  MlpOp(cl::Context& context, const model::ParameterLayout& layout);

  // outputs [n] of inputs [n][inputs]; params is the whole parameter buffer.
  void forward(const cl::Buffer<float>& params, const cl::Buffer<float>& inputs,
               cl::Buffer<float>& outputs);
  // grad (whole buffer, not cleared) += weight gradient of sum(d_outputs * outputs);
  // d_inputs [n][inputs] = d_outputs * doutput/dinput.
  void backward(const cl::Buffer<float>& params, const cl::Buffer<float>& inputs,
                const cl::Buffer<float>& d_outputs, cl::Buffer<float>& grad,
                cl::Buffer<float>& d_inputs);

 private:
  cl::Context& context_;
  model::ParameterLayout layout_;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel forward_;
  cl::Kernel backward_;
};

}  // namespace riner::ops
