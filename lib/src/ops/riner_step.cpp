#include "ops/riner_step.hpp"

#include <algorithm>

#include "ops/model_program.hpp"
#include "riner/error.hpp"

namespace riner::ops {

namespace {

// Fewer samples than this per slice of the MLP gradient cost more in partial sums than they
// save in parallelism.
constexpr std::size_t kMinSliceSamples = 64;

// Samples per work-item of the lanes kernels (riner_step_lanes.cl).
constexpr std::size_t kLanes = 16;

std::vector<std::string> step_sources() {
  return {"common",     "hash_grid",        "mlp",          "ray_sum",           "sample_cache",
          "riner_step", "riner_step_lanes", "mlp_gradient", "hash_grid_gradient"};
}

}  // namespace

void set_batch_shape(const model::PackedBatch& b, StepParams& p) {
  p.n_batch = b.n_batch;
  p.n_samples = b.n_samples;
  p.n_elements = b.n_elements;
  p.rays_at = b.rays_at;
  p.offsets_at = b.offsets_at;
  p.weights_at = b.weights_at;
  p.element_rays_at = b.element_rays_at;
  p.elements_at = b.elements_at;
  p.level_weights_at = b.level_weights_at;
  p.segments_at = b.segments_at;
  p.rho_at = b.rho_at;
}

RinerStepOp::RinerStepOp(cl::Context& context, const model::ParameterLayout& layout,
                         const ExecutionPlan& plan, std::size_t max_batch)
    : context_(context),
      layout_(layout),
      plan_(plan),
      // sample_cache.cl: features, activations, deltas, d_mu, feature gradients, position.
      cache_rows_(2 * static_cast<std::size_t>(layout.inputs) +
                  2 * static_cast<std::size_t>(layout.hidden_layers) * layout.width + 1 +
                  static_cast<std::size_t>(layout.dims)),
      levels_(upload_levels(context, layout)),
      sums_(context, std::max<std::size_t>(1, max_batch)),
      d_sums_(context, std::max<std::size_t>(1, max_batch)),
      ray_grads_(context, std::max<std::size_t>(1, max_batch)),
      scratch_(context, std::max<std::size_t>(1, max_batch)),
      partials_(context, plan.gradient_slices * layout.mlp_params),
      program_(context.program(
          step_sources(),
          model_build_options(layout, plan.kind == PlanKind::kGpu, plan.float_atomics) +
              " -cl-mad-enable")),
      forward_(*program_, "riner_step_forward"),
      forward_lanes_(*program_, "riner_step_forward_lanes"),
      loss_(*program_, "riner_step_loss"),
      backward_(*program_, "riner_step_backward"),
      backward_lanes_(*program_, "riner_step_backward_lanes"),
      mlp_gradient_(*program_,
                    plan.kind == PlanKind::kCpu ? "mlp_gradient_blocked" : "mlp_gradient_partial"),
      grid_gradient_(*program_, "hash_grid_gradient_accumulate"),
      evaluate_(*program_, "riner_step_field_evaluate"),
      // The lanes kernels leave the grid's gradient to hash_grid_gradient.cl: the CPU plan's.
      shape_(plan.kind == PlanKind::kCpu ? Shape::kLanes : Shape::kPerSample) {}

void RinerStepOp::use_shape(Shape shape) {
  if (shape == Shape::kLanes && plan_.kind != PlanKind::kCpu)
    throw Error("riner_step: the lanes shape needs the CPU plan (the grid reduced by ownership)");
  shape_ = shape;
}

void RinerStepOp::reserve_samples(std::size_t n) {
  // The lanes kernels write whole vectors of 16 (their last one padded).
  const std::size_t rows = (n + kLanes - 1) / kLanes * kLanes;
  if (rows <= cache_stride_ && cache_stride_ > 0) return;
  // Room to grow, and a multiple of 16 so each cache row starts 64-byte aligned.
  const std::size_t capacity = (std::max<std::size_t>(rows + rows / 4, 64) + 15) / 16 * 16;
  mu_dx_ = cl::Buffer<float>(context_, capacity);
  cache_ = cl::Buffer<float>(context_, capacity * cache_rows_);
  cache_stride_ = capacity;
}

void RinerStepOp::step(StepParams p, const cl::Buffer<cl_uint>& batch, const StepScan& scan,
                       const cl::Buffer<float>& params, cl::Buffer<float>& grad,
                       cl::Buffer<float>& history) {
  if (params.size() != layout_.total || grad.size() != layout_.total || sums_.size() < p.n_batch ||
      history.size() < 2 * (static_cast<std::size_t>(p.history_slot) + 1)) {
    throw Error("riner_step: buffer sizes do not match the layout");
  }
  reserve_samples(p.n_samples);
  p.cache_stride = static_cast<cl_uint>(cache_stride_);
  p.alpha_offset = static_cast<cl_uint>(layout_.alpha_offset);
  p.beta_offset = static_cast<cl_uint>(layout_.beta_offset);
  p.mlp_offset = static_cast<cl_uint>(layout_.mlp_offset);
  const std::size_t samples = p.n_samples;
  const bool lanes = shape_ == Shape::kLanes;
  const std::size_t lane_items = (samples + kLanes - 1) / kLanes;
  // The plan's group counts samples; a lanes work-item holds 16.
  const std::size_t lane_group = std::max<std::size_t>(1, plan_.sample_group / kLanes);
  if (samples > 0 && lanes) {
    forward_lanes_.set_args(p, batch, levels_, params, mu_dx_, cache_);
    context_.launch(forward_lanes_, lane_items, lane_group);
  } else if (samples > 0) {
    forward_.set_args(p, batch, levels_, params, mu_dx_, cache_);
    context_.launch(forward_, samples, plan_.sample_group);
  }
  loss_.set_args(p, batch, mu_dx_, params, *scan.invalid_readings, *scan.response_slots, grad,
                 sums_, d_sums_, ray_grads_, history, scratch_,
                 cl::LocalMemory{plan_.loss_group * sizeof(float)});
  context_.launch(loss_, plan_.loss_group, plan_.loss_group);
  slices_ = 0;
  if (samples == 0) return;
  if (lanes) {
    backward_lanes_.set_args(p, batch, levels_, params, d_sums_, cache_);
    context_.launch(backward_lanes_, lane_items, lane_group);
  } else {
    backward_.set_args(p, batch, levels_, params, d_sums_, cache_, grad);
    context_.launch(backward_, samples, plan_.sample_group);
  }
  if (plan_.kind == PlanKind::kCpu) {
    const auto bands = static_cast<cl_uint>(plan_.grid_bands);
    grid_gradient_.set_args(p.n_samples, bands, p.cache_stride, levels_, cache_, grad);
    context_.launch(grid_gradient_, static_cast<std::size_t>(layout_.levels) * bands, 1);
  }
  slices_ = std::clamp<std::size_t>(samples / kMinSliceSamples, 1, plan_.gradient_slices);
  const std::size_t chunk = ((samples + slices_ - 1) / slices_ + 3) / 4 * 4;
  slices_ = (samples + chunk - 1) / chunk;
  if (plan_.kind == PlanKind::kCpu) {  // mlp_gradient_blocked forms the last layer's deltas
    mlp_gradient_.set_args(p.n_samples, static_cast<cl_uint>(chunk), p.cache_stride, cache_, params,
                           p.mlp_offset, partials_);
  } else {
    mlp_gradient_.set_args(p.n_samples, static_cast<cl_uint>(chunk), p.cache_stride, cache_,
                           partials_);
  }
  context_.launch(mlp_gradient_, slices_ * plan_.gradient_group, plan_.gradient_group);
}

void RinerStepOp::evaluate(cl_uint first, cl_uint n, const std::vector<std::size_t>& shape,
                           float voxel_mm, float extent_mm, const cl::Buffer<float>& level_weights,
                           const cl::Buffer<float>& params, cl::Buffer<float>& out) {
  const std::size_t rank = shape.size();
  FieldGrid g;
  g.n = n;
  g.first = first;
  g.nx = static_cast<cl_uint>(shape[rank - 1]);
  g.ny = static_cast<cl_uint>(shape[rank - 2]);
  g.nz = static_cast<cl_uint>(rank == 3 ? shape[0] : 1);
  g.voxel = voxel_mm;
  g.extent = extent_mm;
  g.mlp_offset = static_cast<cl_uint>(layout_.mlp_offset);
  evaluate_.set_args(g, levels_, level_weights, params, out);
  context_.launch(evaluate_, n);
}

}  // namespace riner::ops
