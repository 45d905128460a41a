// CPU twin of kernels/riner_step.cl: the loss of one batch of rays and its gradient over every
// parameter (grid, MLP, alpha0, beta0), in double. The reference engine trains with it; the
// OpenCL step is checked against it, and it against finite differences.
#pragma once

#include <cstdint>
#include <vector>

#include "model/batch_sampler.hpp"
#include "model/parameter_layout.hpp"
#include "model/ray_segments.hpp"
#include "model/response_map.hpp"

namespace riner::ref {

struct StepInputs {
  const model::ParameterLayout* layout = nullptr;
  const model::RaySegments* segments = nullptr;
  const std::vector<float>* measurement = nullptr;  // rho per ray id
  double starved_floor = 0.0;                       // the bound of a +inf reading
  std::size_t elements_per_view = 0;                // n_u * n_v
  bool jitter = true;
  std::uint32_t seed = 0;
  std::uint32_t step = 0;
  double lambda = 0.01;
  double ring_lambda = 0.0;
  double relative_beta_threshold = 0.0;  // see riner_step.cl, riner_step_loss
  double data_weight = 1.0;
  std::vector<float> level_weights;  // per encoding level (empty: all 1)
  // Beta warm-up (riner_step.cl): while hold_valid_beta, beta0 of every element with no
  // invalid reading (invalid_readings[e] == 0) gets no gradient.
  bool hold_valid_beta = false;
  const std::vector<std::uint32_t>* invalid_readings = nullptr;  // per response slot
  // Which alpha0/beta0 each reading uses (null: its element's, as ResponseMap(elements)).
  const model::ResponseMap* responses = nullptr;

  std::size_t slot(std::uint32_t ray) const {
    const std::size_t e = ray % elements_per_view;
    return responses ? responses->slot(e, ray / elements_per_view) : e;
  }
};

struct StepResult {
  double data_loss = 0.0;
  double penalty = 0.0;
  std::vector<double> grad;    // over the whole parameter buffer
  std::vector<double> sums;    // per batch ray: sum of mu dx
  std::vector<double> d_sums;  // per batch ray: dloss/dsum (ring prior included)
};

StepResult riner_step(const StepInputs& in, const model::Batch& batch,
                      const std::vector<double>& params, bool with_gradient = true);

// The ring prior of kernels/riner_step.cl on the batch's views x elements block: returns its
// value and adds its gradient with respect to the ray sums into d_sums (when not null).
double ring_prior(const model::Batch& batch, const std::vector<double>& sums, double ring_lambda,
                  std::vector<double>* d_sums);

// Jitter of sample k of a ray at a step, shared with the kernels (model/counter_rng.hpp).
float sample_jitter(std::uint32_t seed, std::uint32_t step, std::uint32_t ray, std::uint32_t k);

// mu at normalised positions [n][dims] (evaluation of the trained field).
std::vector<float> riner_step_field_evaluate(const model::ParameterLayout& l,
                                  const std::vector<double>& params,
                                  const std::vector<float>& positions,
                                  const std::vector<float>& level_weights);

// Multiplies level l's values by level_weights[l] (no-op when empty).
void scale_levels(const model::ParameterLayout& l, const std::vector<float>& level_weights,
                  double* values);

}  // namespace riner::ref
