// Host side of kernels/riner_step.cl: the training step (forward ray sums over lanes of rays,
// the batch's loss, the backward pass over lanes) and the evaluation of the field.
#pragma once

#include <memory>

#include "cl/buffer.hpp"
#include "cl/program.hpp"
#include "model/parameter_layout.hpp"

namespace riner::ops {

struct StepArgs {
  const cl::Buffer<cl_uint>* rays;         // the batch's ray ids
  const cl::Buffer<cl_uint>* offsets;      // n_batch + 1: batch ray b owns samples
                                           // offsets[b] .. offsets[b + 1] (its segment count)
  const cl::Buffer<cl_uint>* sample_rays;  // n_samples: the batch ray of each sample
  const cl::Buffer<cl_float8>* segments;   // every ray of the scan
  const cl::Buffer<float>* rho;            // every ray of the scan
  const cl::Buffer<float>* weights;        // data-term weight per batch ray
  const cl::Buffer<float>* level_weights;  // per encoding level
  const cl::Buffer<cl_uint>* elements;     // the batch's distinct elements
  cl_uint n_batch;
  cl_uint n_samples;  // offsets[n_batch]
  cl_uint n_elements;
  cl_uint elements_per_view;
  cl_uint seed;
  cl_uint step;
  bool jitter;
  float lambda;
  float relative_threshold;  // 0: the absolute balance
  float data_weight;
  cl_uint block_first;
  cl_uint block_views;
  cl_uint block_elements;
  float ring_lambda;
  bool hold_valid_beta;                         // beta warm-up: see invalid_readings
  const cl::Buffer<cl_uint>* invalid_readings;  // per element: its non-finite readings; while
                                                // hold_valid_beta, beta0 of elements with none
                                                // gets no gradient
};

class RinerStepOp {
 public:
  // atomic: one shared gradient (lanes = rays); otherwise lanes own partial gradients.
  // The per-sample buffers grow to the largest batch seen.
  RinerStepOp(cl::Context& context, const model::ParameterLayout& layout, bool atomic,
              std::size_t max_batch);

  // Adds the step's gradient into grad (n_lanes partial gradients of layout.total each, or
  // one when atomic); loss[0] = data term, loss[1] = penalties.
  void step(const StepArgs& args, cl_uint n_lanes, const cl::Buffer<float>& params,
            cl::Buffer<float>& grad, cl::Buffer<float>& loss);

  // out[first .. first + n) = mu at the centres of voxels of the grid [nz][ny][nx].
  void evaluate(cl_uint first, cl_uint n, const std::vector<std::size_t>& volume_shape,
                float voxel_mm, float extent_mm, const cl::Buffer<float>& level_weights,
                const cl::Buffer<float>& params, cl::Buffer<float>& out);

 private:
  cl::Context& context_;
  model::ParameterLayout layout_;
  bool atomic_;
  cl::Buffer<model::GridLevel> levels_;
  cl::Buffer<float> sums_;
  cl::Buffer<float> d_sums_;
  cl::Buffer<float> scratch_;
  cl::Buffer<float> mu_dx_;  // per sample
  cl::Buffer<float> cache_;  // per sample: features and activations (SAMPLE_CACHE floats)
  std::size_t cache_stride_ = 0;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel forward_;
  cl::Kernel loss_;
  cl::Kernel backward_;
  cl::Kernel evaluate_;
};

}  // namespace riner::ops
