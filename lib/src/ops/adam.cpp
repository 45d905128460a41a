#include "ops/adam.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "riner/error.hpp"

namespace riner::ops {

AdamOp::AdamOp(cl::Context& context, std::size_t n_params)
    : context_(context),
      n_params_(n_params),
      m_(context, n_params),
      v_(context, n_params),
      no_slices_(context, 1),
      program_(context.program({"common", "adam"})),
      kernel_(*program_, "adam_step") {
  reset();
}

void AdamOp::reset() {
  const std::vector<float> zeros(n_params_, 0.0f);
  m_.write(zeros);
  v_.write(zeros);
}

void AdamOp::set_moments(std::span<const float> m, std::span<const float> v) {
  if (m.size() != n_params_ || v.size() != n_params_) {
    throw Error("adam: moments of " + std::to_string(m.size()) + " values for " +
                std::to_string(n_params_) + " parameters");
  }
  m_.write(m);
  v_.write(v);
}

void AdamOp::step(const AdamSettings& s, int step, cl::Buffer<float>& params,
                  cl::Buffer<float>& grad, const GradientSlices& slices) {
  const bool sliced = slices.buffer != nullptr && slices.slices > 0;
  if (params.size() != n_params_ || grad.size() != n_params_ ||
      (sliced && (slices.offset + slices.count > n_params_ ||
                  slices.buffer->size() < slices.count * slices.slices))) {
    throw Error("adam_step: buffer sizes do not match");
  }
  const double bias1 = 1.0 - std::pow(s.beta1, step);
  const double bias2 = 1.0 - std::pow(s.beta2, step);
  AdamParams p;
  p.n = static_cast<cl_uint>(n_params_);
  p.step_size = static_cast<float>(s.learning_rate / bias1);
  p.alpha_offset = static_cast<cl_uint>(std::min(s.alpha_offset, n_params_));
  p.alpha_step_size = static_cast<float>(s.alpha_learning_rate / bias1);
  p.beta_offset = static_cast<cl_uint>(std::min(s.beta_offset, n_params_));
  p.beta_step_size = static_cast<float>(s.beta_learning_rate / bias1);
  p.beta1 = static_cast<float>(s.beta1);
  p.beta2 = static_cast<float>(s.beta2);
  p.inv_sqrt_bias2 = static_cast<float>(1.0 / std::sqrt(bias2));
  p.epsilon = static_cast<float>(s.epsilon);
  p.sparse_below = static_cast<cl_uint>(std::min(s.sparse_below, n_params_));
  if (sliced) {
    p.partial_offset = static_cast<cl_uint>(slices.offset);
    p.partial_count = static_cast<cl_uint>(slices.count);
    p.n_partials = static_cast<cl_uint>(slices.slices);
  }
  kernel_.set_args(p, params, m_, v_, grad, sliced ? *slices.buffer : no_slices_);
  // Groups of ADAM_LANES (adam.cl) parameters, then one work-item per parameter with partials.
  constexpr std::size_t kLanes = 8;
  context_.launch(kernel_, (n_params_ + kLanes - 1) / kLanes + (sliced ? slices.count : 0));
}

}  // namespace riner::ops
