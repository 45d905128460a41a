#include "ops/riner_step.hpp"

#include <algorithm>

#include "ops/model_program.hpp"
#include "riner/error.hpp"

namespace riner::ops {

namespace {
constexpr std::size_t kForwardGroup = 64;
}  // namespace

RinerStepOp::RinerStepOp(cl::Context& context, const model::ParameterLayout& layout, bool atomic,
                         std::size_t max_batch)
    : context_(context),
      layout_(layout),
      atomic_(atomic),
      levels_(upload_levels(context, layout)),
      sums_(context, max_batch),
      d_sums_(context, max_batch),
      scratch_(context, max_batch),
      program_(context.program({"common", "hash_grid", "mlp", "ray_sum", "riner_step"},
                               model_build_options(layout, atomic))),
      forward_(*program_, "riner_step_forward"),
      loss_(*program_, "riner_step_loss"),
      backward_(*program_, "riner_step_backward"),
      evaluate_(*program_, "field_evaluate") {}

void RinerStepOp::step(const StepArgs& a, cl_uint n_lanes, const cl::Buffer<float>& params,
                       cl::Buffer<float>& grad, cl::Buffer<float>& loss) {
  const std::size_t gradients = atomic_ ? 1 : n_lanes;
  if (params.size() != layout_.total || grad.size() != gradients * layout_.total ||
      loss.size() < 2 || a.rays->size() < a.n_batch || sums_.size() < a.n_batch) {
    throw Error("riner_step: buffer sizes do not match the layout");
  }
  const auto mlp = static_cast<cl_uint>(layout_.mlp_offset);
  const auto jitter = static_cast<cl_int>(a.jitter);
  const std::size_t cache_floats = static_cast<std::size_t>(layout_.inputs) +
                                   static_cast<std::size_t>(layout_.hidden_layers) * layout_.width;
  if (mu_dx_.size() < a.n_samples || mu_dx_.size() == 0) {
    const std::size_t capacity = std::max<std::size_t>(1, a.n_samples + a.n_samples / 4);
    mu_dx_ = cl::Buffer<float>(context_, capacity);
    cache_ = cl::Buffer<float>(context_, capacity * cache_floats);
    cache_stride_ = capacity;
  }
  const auto stride_samples = static_cast<cl_uint>(cache_stride_);
  if (a.n_samples > 0) {
    forward_.set_args(a.n_samples, *a.sample_rays, *a.offsets, *a.rays, *a.segments, levels_,
                      *a.level_weights, params, mlp, a.seed, a.step, jitter, mu_dx_, cache_,
                      stride_samples);
    // A fixed work-group size: the sample count changes every step, and PoCL compiles a kernel
    // variant for every distinct work-group size it is asked for.
    context_.launch(forward_, a.n_samples, kForwardGroup);
  }
  loss_.set_args(a.n_batch, *a.offsets, mu_dx_, *a.rays, sums_, *a.rho, *a.weights,
                 a.elements_per_view, params, static_cast<cl_uint>(layout_.alpha_offset),
                 static_cast<cl_uint>(layout_.beta_offset), a.n_elements, *a.elements, a.lambda,
                 a.relative_threshold, a.data_weight, a.block_first, a.block_views,
                 a.block_elements, a.ring_lambda, static_cast<cl_uint>(a.hold_valid_beta),
                 *a.invalid_readings, grad, d_sums_, loss, scratch_);
  context_.launch(loss_, 1, 1);
  // Lanes are independent work-groups of one work-item: on a CPU each runs as plain code.
  const auto stride = static_cast<cl_uint>(atomic_ ? 0 : layout_.total);
  backward_.set_args(n_lanes, a.n_batch, *a.offsets, *a.rays, *a.segments, levels_,
                     *a.level_weights, params, grad, stride, mlp, a.seed, a.step, jitter, d_sums_,
                     cache_, stride_samples);
  context_.launch(backward_, n_lanes, 1);
}

void RinerStepOp::evaluate(cl_uint first, cl_uint n, const std::vector<std::size_t>& shape,
                           float voxel_mm, float extent_mm, const cl::Buffer<float>& level_weights,
                           const cl::Buffer<float>& params, cl::Buffer<float>& out) {
  const std::size_t rank = shape.size();
  const auto nx = static_cast<cl_uint>(shape[rank - 1]);
  const auto ny = static_cast<cl_uint>(shape[rank - 2]);
  const auto nz = static_cast<cl_uint>(rank == 3 ? shape[0] : 1);
  evaluate_.set_args(n, first, nx, ny, nz, voxel_mm, extent_mm, levels_, level_weights, params,
                     static_cast<cl_uint>(layout_.mlp_offset), out);
  context_.launch(evaluate_, n);
}

}  // namespace riner::ops
