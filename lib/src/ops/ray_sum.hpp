// Host side of kernels/ray_sum.cl: ray sums, the forward model and the loss for explicit
// per-sample mu (the unfused path, and the kernel's cross-check).
#pragma once

#include <memory>

#include "cl/buffer.hpp"
#include "cl/program.hpp"

namespace riner::ops {

class RaySumOp {
 public:
  explicit RaySumOp(cl::Context& context);

  struct Rays {
    const cl::Buffer<cl_uint>* offsets;   // n + 1 sample offsets
    const cl::Buffer<float>* dx;          // n
    const cl::Buffer<cl_uint>* elements;  // n
    const cl::Buffer<float>* rho;         // n
  };
  // d_mu per sample and loss per ray; alpha0/beta0 gradients added (atomically) into d_alpha0,
  // d_beta0 (per element). A reading of +inf is a bound, rho >= floor.
  void loss(const Rays& rays, const cl::Buffer<float>& mu, const cl::Buffer<float>& alpha0,
            const cl::Buffer<float>& beta0, float weight, float floor, cl::Buffer<float>& d_mu,
            cl::Buffer<float>& loss, cl::Buffer<float>& d_alpha0, cl::Buffer<float>& d_beta0);

 private:
  cl::Context& context_;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel kernel_;
};

}  // namespace riner::ops
