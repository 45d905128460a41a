// Host side of kernels/riner_step.cl (with the gradient reductions of mlp_gradient.cl and
// hash_grid_gradient.cl): one training step, shaped by an execution plan, and the evaluation of
// the field.
#pragma once

#include <memory>

#include "cl/buffer.hpp"
#include "cl/program.hpp"
#include "model/packed_batch.hpp"
#include "model/parameter_layout.hpp"
#include "riner/execution_plan.hpp"

namespace riner::ops {

// Host mirror of StepParams in kernels/sample_cache.cl (29 four-byte members).
struct StepParams {
  cl_uint n_batch = 0;
  cl_uint n_samples = 0;
  cl_uint n_elements = 0;
  cl_uint rays_at = 0;
  cl_uint offsets_at = 0;
  cl_uint weights_at = 0;
  cl_uint element_rays_at = 0;
  cl_uint elements_at = 0;
  cl_uint level_weights_at = 0;
  cl_uint elements_per_view = 0;
  cl_uint alpha_offset = 0;
  cl_uint beta_offset = 0;
  cl_uint mlp_offset = 0;
  cl_uint seed = 0;
  cl_uint step = 0;
  cl_uint jitter = 0;
  cl_uint hold_valid_beta = 0;
  cl_uint history_slot = 0;
  float lambda = 0.0f;
  float relative_beta_threshold = 0.0f;  // 0: the absolute balance
  float data_weight = 1.0f;
  float ring_lambda = 0.0f;
  cl_uint block_first = 0;
  cl_uint block_views = 0;
  cl_uint block_elements = 0;
  cl_uint cache_stride = 0;  // set by RinerStepOp
  cl_uint segments_at = 0;
  cl_uint rho_at = 0;
  float starved_floor = 0.0f;  // the bound of a +inf reading (model/starved_readings.hpp)
};
static_assert(sizeof(StepParams) == 116);

// Host mirror of FieldGrid in kernels/riner_step.cl: which voxels of which grid one launch of
// riner_step_field_evaluate evaluates.
struct FieldGrid {
  cl_uint n = 0;
  cl_uint first = 0;
  cl_uint nx = 0;
  cl_uint ny = 0;
  cl_uint nz = 0;
  float voxel = 0.0f;
  float extent = 0.0f;
  cl_uint mlp_offset = 0;
};
static_assert(sizeof(FieldGrid) == 32, "must match FieldGrid in riner_step.cl");

// The batch's sizes and section starts (the rest of StepParams is the step's settings).
void set_batch_shape(const model::PackedBatch& batch, StepParams& p);

// The scan-wide inputs of every step (the rays' segments and readings come in the batch).
struct StepScan {
  const cl::Buffer<cl_uint>* invalid_readings;  // per response slot: its non-finite readings
  const cl::Buffer<cl_uint>* response_slots;    // model/response_map.hpp's table
};

class RinerStepOp {
 public:
  // max_batch: the most rays of a step. Per-sample buffers grow to the largest step seen.
  RinerStepOp(cl::Context& context, const model::ParameterLayout& layout, const ExecutionPlan& plan,
              std::size_t max_batch);

  // The per-sample kernels' shape: one sample per work-item, or 16 in float16 lanes
  // (riner_step_lanes.cl; the CPU plan's). The same values either way; tests compare them.
  enum class Shape { kPerSample, kLanes };
  void use_shape(Shape shape);

  // Enqueues the step's kernels: grad (zero on entry; Adam zeroes it after use) receives the
  // grid, alpha0 and beta0 gradients, mlp_partials() the MLP's (mlp_slices() slices of
  // layout.mlp_params), history[2 p.history_slot ..] the data term and the penalties.
  void step(StepParams p, const cl::Buffer<cl_uint>& batch, const StepScan& scan,
            const cl::Buffer<float>& params, cl::Buffer<float>& grad, cl::Buffer<float>& history);

  const cl::Buffer<float>& mlp_partials() const { return partials_; }
  // The last step's ray sums and their loss gradients (for cross-checks).
  const cl::Buffer<float>& ray_sums() const { return sums_; }
  const cl::Buffer<float>& ray_sum_gradients() const { return d_sums_; }
  std::size_t mlp_slices() const { return slices_; }

  // out[first .. first + n) = mu at the centres of voxels of the grid [nz][ny][nx].
  void evaluate(cl_uint first, cl_uint n, const std::vector<std::size_t>& volume_shape,
                float voxel_mm, float extent_mm, const cl::Buffer<float>& level_weights,
                const cl::Buffer<float>& params, cl::Buffer<float>& out);

 private:
  void reserve_samples(std::size_t n_samples);

  cl::Context& context_;
  model::ParameterLayout layout_;
  ExecutionPlan plan_;
  std::size_t cache_rows_;
  cl::Buffer<model::GridLevel> levels_;
  cl::Buffer<float> sums_;
  cl::Buffer<float> d_sums_;
  cl::Buffer<cl_float2> ray_grads_;
  cl::Buffer<float> scratch_;
  cl::Buffer<float> mu_dx_;  // per sample
  cl::Buffer<float> cache_;  // per sample: cache_rows_ floats (kernels/sample_cache.cl)
  std::size_t cache_stride_ = 0;
  cl::Buffer<float> partials_;
  std::size_t slices_ = 0;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel forward_;
  cl::Kernel forward_lanes_;
  cl::Kernel loss_;
  cl::Kernel backward_;
  cl::Kernel backward_lanes_;
  cl::Kernel mlp_gradient_;
  cl::Kernel grid_gradient_;
  cl::Kernel evaluate_;
  Shape shape_;
};

}  // namespace riner::ops
