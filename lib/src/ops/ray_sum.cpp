#include "ops/ray_sum.hpp"

#include "riner/error.hpp"

namespace riner::ops {

RaySumOp::RaySumOp(cl::Context& context)
    : context_(context),
      program_(context.program({"common", "ray_sum"}, "-D ATOMIC_GRADIENTS")),
      kernel_(*program_, "ray_sum_loss") {}

void RaySumOp::loss(const Rays& rays, const cl::Buffer<float>& mu, const cl::Buffer<float>& alpha0,
                    const cl::Buffer<float>& beta0, float weight, float floor,
                    cl::Buffer<float>& d_mu, cl::Buffer<float>& loss, cl::Buffer<float>& d_alpha0,
                    cl::Buffer<float>& d_beta0) {
  const auto n = static_cast<cl_uint>(rays.dx->size());
  if (rays.offsets->size() != n + 1u || rays.elements->size() != n || rays.rho->size() != n ||
      loss.size() != n || d_mu.size() != mu.size()) {
    throw Error("ray_sum_loss: buffer sizes disagree");
  }
  kernel_.set_args(n, *rays.offsets, mu, *rays.dx, *rays.elements, *rays.rho, alpha0, beta0, weight,
                   floor, d_mu, loss, d_alpha0, d_beta0);
  context_.launch(kernel_, n);
}

}  // namespace riner::ops
