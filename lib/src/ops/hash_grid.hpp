// Host side of kernels/hash_grid.cl: the grid encoding of explicit points and its gradient
// scatter (atomic: many points share the gradient buffer).
#pragma once

#include <memory>

#include "cl/buffer.hpp"
#include "cl/program.hpp"
#include "model/parameter_layout.hpp"

namespace riner::ops {

class HashGridOp {
 public:
  HashGridOp(cl::Context& context, const model::ParameterLayout& layout);

  // features [n][inputs] of positions [n][dims], reading the tables in params.
  void forward(const cl::Buffer<float>& params, const cl::Buffer<float>& positions,
               cl::Buffer<float>& features);
  // grad += the gradient of sum(d_features * features) (grad is not cleared).
  void backward(const cl::Buffer<float>& positions, const cl::Buffer<float>& d_features,
                cl::Buffer<float>& grad);

 private:
  cl::Context& context_;
  model::ParameterLayout layout_;
  cl::Buffer<model::GridLevel> levels_;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel forward_;
  cl::Kernel backward_;
};

}  // namespace riner::ops
