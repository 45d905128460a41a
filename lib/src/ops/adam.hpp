// Host side of kernels/adam.cl: Adam over the flat parameter buffer, taking the gradient from
// one full-size buffer (cleared as it goes) plus split-K partial sums over a range of it.
#pragma once

#include <memory>
#include <span>

#include "cl/buffer.hpp"
#include "cl/program.hpp"
#include "model/adam_settings.hpp"

namespace riner::ops {

using AdamSettings = model::AdamSettings;

// `slices` partial sums of `count` values each (slice p at [p count, (p + 1) count)), added to
// the gradient of parameters [offset, offset + count).
struct GradientSlices {
  const cl::Buffer<float>* buffer = nullptr;
  std::size_t offset = 0;
  std::size_t count = 0;
  std::size_t slices = 0;
};

// Host mirror of AdamParams in kernels/adam.cl: one step's sizes and settings.
struct AdamParams {
  cl_uint n = 0;
  float step_size = 0.0f;
  cl_uint alpha_offset = 0;
  float alpha_step_size = 0.0f;
  cl_uint beta_offset = 0;
  float beta_step_size = 0.0f;
  float beta1 = 0.0f;
  float beta2 = 0.0f;
  float inv_sqrt_bias2 = 0.0f;
  float epsilon = 0.0f;
  cl_uint partial_offset = 0;
  cl_uint partial_count = 0;
  cl_uint n_partials = 0;
  cl_uint sparse_below = 0;
};
static_assert(sizeof(AdamParams) == 56, "must match AdamParams in adam.cl");

class AdamOp {
 public:
  AdamOp(cl::Context& context, std::size_t n_params);

  // step counts from 1; grad holds n_params gradients (zeroed after).
  void step(const AdamSettings& settings, int step, cl::Buffer<float>& params,
            cl::Buffer<float>& grad, const GradientSlices& slices = {});

  // Back to fresh moments.
  void reset();

  // The first and second moments (a checkpoint's), and back from one.
  const cl::Buffer<float>& first_moments() const { return m_; }
  const cl::Buffer<float>& second_moments() const { return v_; }
  void set_moments(std::span<const float> m, std::span<const float> v);

 private:
  cl::Context& context_;
  std::size_t n_params_;
  cl::Buffer<float> m_;
  cl::Buffer<float> v_;
  cl::Buffer<float> no_slices_;  // a valid argument when there are none
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel kernel_;
};

}  // namespace riner::ops
