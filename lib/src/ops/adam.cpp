#include "ops/adam.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "riner/error.hpp"

namespace riner::ops {

AdamOp::AdamOp(cl::Context& context, std::size_t n_params, std::size_t n_partials)
    : context_(context),
      n_params_(n_params),
      n_partials_(n_partials),
      m_(context, n_params),
      v_(context, n_params),
      program_(context.program({"common", "adam"})),
      kernel_(*program_, "adam_step") {
  reset();
}

void AdamOp::reset() {
  const std::vector<float> zeros(n_params_, 0.0f);
  m_.write(zeros);
  v_.write(zeros);
}

void AdamOp::step(const AdamSettings& s, int step, cl::Buffer<float>& params,
                  cl::Buffer<float>& partials) {
  if (params.size() != n_params_ || partials.size() != n_params_ * n_partials_) {
    throw Error("adam_step: buffer sizes do not match");
  }
  const double bias1 = 1.0 - std::pow(s.beta1, step);
  const double bias2 = 1.0 - std::pow(s.beta2, step);
  kernel_.set_args(static_cast<cl_uint>(n_params_), static_cast<cl_uint>(n_partials_),
                   static_cast<float>(s.learning_rate / bias1),
                   static_cast<cl_uint>(std::min(s.alpha_offset, n_params_)),
                   static_cast<float>(s.alpha_learning_rate / bias1),
                   static_cast<cl_uint>(std::min(s.beta_offset, n_params_)),
                   static_cast<float>(s.beta_learning_rate / bias1), static_cast<float>(s.beta1),
                   static_cast<float>(s.beta2), static_cast<float>(1.0 / std::sqrt(bias2)),
                   static_cast<float>(s.epsilon), params, m_, v_, partials);
  context_.launch(kernel_, n_params_);
}

}  // namespace riner::ops
