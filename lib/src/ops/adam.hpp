// Host side of kernels/adam.cl: Adam over the flat parameter buffer, reducing and clearing the
// lanes' partial gradients as it goes.
#pragma once

#include <memory>

#include "cl/buffer.hpp"
#include "cl/program.hpp"
#include "model/adam_settings.hpp"

namespace riner::ops {

using AdamSettings = model::AdamSettings;

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
