// Host side of kernels/vector_ops.cl: element-wise vector kernels.
#pragma once

#include "cl/buffer.hpp"
#include "cl/context.hpp"
#include "cl/program.hpp"

namespace riner::ops {

class VectorOps {
 public:
  explicit VectorOps(cl::Context& context);

  // y += a * x
  void axpy(float a, const cl::Buffer<float>& x, cl::Buffer<float>& y);
  // total[0] += sum(x); float atomics, so the last bits depend on thread order.
  void sum(const cl::Buffer<float>& x, cl::Buffer<float>& total);
  // y[i] = value
  void fill(cl::Buffer<float>& y, float value);

 private:
  cl::Context& context_;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel axpy_;
  cl::Kernel sum_;
  cl::Kernel fill_;
};

}  // namespace riner::ops
