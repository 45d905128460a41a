// Host side of kernels/adam.cl: Adam over the flat parameter buffer, reducing and clearing the
// lanes' partial gradients as it goes.
#pragma once

#include <memory>

#include "cl/buffer.hpp"
#include "cl/program.hpp"

namespace riner::ops {

struct AdamSettings {
  double learning_rate = 1e-3;
  // alpha0 and beta0 (from these offsets on) have learning rates of their own.
  std::size_t alpha_offset = static_cast<std::size_t>(-1);
  double alpha_learning_rate = 1e-3;
  std::size_t beta_offset = static_cast<std::size_t>(-1);
  double beta_learning_rate = 1e-3;
  double beta1 = 0.9;
  double beta2 = 0.999;
  double epsilon = 1e-8;
};

class AdamOp {
 public:
  AdamOp(cl::Context& context, std::size_t n_params, std::size_t n_partials);

  // step counts from 1; partials holds n_partials gradients of n_params each (zeroed after).
  void step(const AdamSettings& settings, int step, cl::Buffer<float>& params,
            cl::Buffer<float>& partials);

  // Back to fresh moments.
  void reset();

 private:
  cl::Context& context_;
  std::size_t n_params_;
  std::size_t n_partials_;
  cl::Buffer<float> m_;
  cl::Buffer<float> v_;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel kernel_;
};

}  // namespace riner::ops
