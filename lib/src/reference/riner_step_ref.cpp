#include "reference/riner_step_ref.hpp"

#include <algorithm>

#include "model/counter_rng.hpp"
#include "reference/hash_grid_ref.hpp"
#include "reference/mlp_ref.hpp"
#include "reference/ray_sum_ref.hpp"
#include "util/parallel.hpp"

namespace riner::ref {

float sample_jitter(std::uint32_t seed, std::uint32_t step, std::uint32_t ray, std::uint32_t k) {
  return model::uniform24(
      model::hash32(k ^ model::hash_keys(model::kJitterStream, seed, step, ray)));
}

void scale_levels(const model::ParameterLayout& l, const std::vector<float>& level_weights,
                  double* values) {
  if (level_weights.empty()) return;
  for (int level = 0; level < l.levels; ++level) {
    for (int f = 0; f < l.features; ++f)
      values[level * l.features + f] *= level_weights[static_cast<std::size_t>(level)];
  }
}

namespace {

// The position of a ray's sample k (jittered like the kernel when the step asks for it).
void sample_at(const StepInputs& in, const model::RaySegment& s, std::uint32_t ray, std::uint32_t k,
               double pos[3]) {
  const float u = in.jitter ? sample_jitter(in.seed, in.step, ray, k) : 0.5f;
  float p[3];
  model::sample_position(s, k, u, p);
  for (int d = 0; d < 3; ++d) pos[d] = p[d];
}

// Every ray's sum of mu dx (threads own disjoint rays).
std::vector<double> ray_sums(const StepInputs& in, const model::Batch& batch,
                             const std::vector<double>& params) {
  const model::ParameterLayout& l = *in.layout;
  std::vector<double> sums(batch.rays.size(), 0.0);
  util::parallel_for(sums.size(), [&](std::size_t begin, std::size_t end) {
    std::vector<double> features(static_cast<std::size_t>(l.inputs));
    for (std::size_t b = begin; b < end; ++b) {
      const std::uint32_t ray = batch.rays[b];
      const model::RaySegment s = (*in.segments)[ray];
      double sum = 0.0;
      for (std::uint32_t k = 0; k < s.count; ++k) {
        double pos[3];
        sample_at(in, s, ray, k, pos);
        hash_grid_encode(l, params.data(), pos, features.data());
        scale_levels(l, in.level_weights, features.data());
        sum += mlp_forward(l, params.data(), features.data());
      }
      sums[b] = sum * s.dx;
    }
  });
  return sums;
}

// lambda, or with a relative threshold, data_weight * threshold * the batch's median ray
// mismatch / 2 where that is larger (riner_step.cl, riner_step_loss); the elements with a
// non-finite reading keep lambda (losses()).
double penalty_weight(const StepInputs& in, const model::Batch& batch,
                      const std::vector<double>& params, const std::vector<double>& sums) {
  const model::ParameterLayout& l = *in.layout;
  const std::size_t n = batch.rays.size();
  if (!(in.relative_beta_threshold > 0.0) || n == 0) return in.lambda;
  std::vector<double> mismatch(n);
  for (std::size_t b = 0; b < n; ++b) {
    const std::uint32_t ray = batch.rays[b];
    mismatch[b] = ray_mismatch(sums[b], params[l.alpha_offset + in.slot(ray)],
                               (*in.measurement)[ray], in.starved_floor);
  }
  std::nth_element(mismatch.begin(), mismatch.begin() + static_cast<long>((n - 1) / 2),
                   mismatch.end());
  const double median = mismatch[(n - 1) / 2];
  return std::max(in.lambda,
                  0.5 * in.data_weight * in.relative_beta_threshold * std::max(median, 1e-3));
}

// The losses in batch order like the kernel: result's losses, d_sums and (with a gradient) the
// alpha0 and beta0 gradients.
void losses(const StepInputs& in, const model::Batch& batch, const std::vector<double>& params,
            bool with_gradient, StepResult& result) {
  const model::ParameterLayout& l = *in.layout;
  const std::size_t n = batch.rays.size();
  result.d_sums.assign(n, 0.0);
  const double weight = penalty_weight(in, batch, params, result.sums);
  const auto beta_learns = [&](std::size_t slot) {
    return !in.hold_valid_beta || (*in.invalid_readings)[slot] != 0;
  };
  std::vector<std::uint8_t> touched(l.elements, 0);
  for (std::size_t b = 0; b < n; ++b) {
    const std::uint32_t ray = batch.rays[b];
    const std::size_t slot = in.slot(ray);
    touched[slot] = 1;
    const RayLoss rl =
        ray_loss(result.sums[b], params[l.alpha_offset + slot], params[l.beta_offset + slot],
                 (*in.measurement)[ray], batch.weights[b], in.starved_floor);
    result.data_loss += rl.loss;
    result.d_sums[b] = rl.d_sum;
    if (with_gradient) {
      result.grad[l.alpha_offset + slot] += rl.d_alpha0;
      if (beta_learns(slot)) result.grad[l.beta_offset + slot] += rl.d_beta0;
    }
  }
  // A penalty per slot the batch reads, element by element and each element's in view order.
  for (std::uint32_t e : batch.elements) {
    std::vector<std::size_t> slots{e};
    if (in.responses) {
      slots.clear();
      for (const model::ResponseMap::Segment& s : in.responses->segments(e))
        slots.push_back(s.slot);
    }
    for (std::size_t slot : slots) {
      if (!touched[slot]) continue;
      double d_beta0 = 0.0;
      const double w =
          in.invalid_readings && (*in.invalid_readings)[slot] != 0 ? in.lambda : weight;
      result.penalty += beta_penalty(params[l.beta_offset + slot], w, &d_beta0);
      if (with_gradient && beta_learns(slot)) result.grad[l.beta_offset + slot] += d_beta0;
    }
  }
  result.penalty += ring_prior(batch, result.sums, in.ring_lambda, &result.d_sums);
}

// The field's gradient from d_sums: threads own contiguous rays and their own gradients,
// summed in order.
void backward(const StepInputs& in, const model::Batch& batch, const std::vector<double>& params,
              StepResult& result) {
  const model::ParameterLayout& l = *in.layout;
  std::vector<std::vector<double>> partials =
      util::parallel_map_chunks(batch.rays.size(), [&](std::size_t begin, std::size_t end) {
        std::vector<double> grad(l.total, 0.0);
        std::vector<double> features(static_cast<std::size_t>(l.inputs));
        std::vector<double> d_features(static_cast<std::size_t>(l.inputs));
        for (std::size_t b = begin; b < end; ++b) {
          const std::uint32_t ray = batch.rays[b];
          const model::RaySegment s = (*in.segments)[ray];
          const double d_mu = result.d_sums[b] * s.dx;
          if (d_mu == 0.0) continue;
          for (std::uint32_t k = 0; k < s.count; ++k) {
            double pos[3];
            sample_at(in, s, ray, k, pos);
            hash_grid_encode(l, params.data(), pos, features.data());
            scale_levels(l, in.level_weights, features.data());
            MlpTrace trace;
            mlp_forward(l, params.data(), features.data(), &trace);
            mlp_backward(l, params.data(), features.data(), trace, d_mu, grad.data(),
                         d_features.data());
            scale_levels(l, in.level_weights, d_features.data());
            hash_grid_scatter(l, pos, d_features.data(), grad.data());
          }
        }
        return grad;
      });
  for (const std::vector<double>& g : partials) {
    for (std::size_t i = 0; i < l.total; ++i) result.grad[i] += g[i];
  }
}

}  // namespace

StepResult riner_step(const StepInputs& in, const model::Batch& batch,
                      const std::vector<double>& params, bool with_gradient) {
  StepResult result;
  if (with_gradient) result.grad.assign(in.layout->total, 0.0);
  result.sums = ray_sums(in, batch, params);
  losses(in, batch, params, with_gradient, result);
  if (with_gradient) backward(in, batch, params, result);
  return result;
}

double ring_prior(const model::Batch& batch, const std::vector<double>& sums, double ring_lambda,
                  std::vector<double>* d_sums) {
  const std::uint32_t V = batch.block_views;
  const std::uint32_t E = batch.block_elements;
  if (ring_lambda <= 0.0 || V == 0 || E < 3) return 0.0;
  double penalty = 0.0;
  for (std::uint32_t e = 1; e + 1 < E; ++e) {
    double r = 0.0;
    for (std::uint32_t v = 0; v < V; ++v) {
      const std::size_t base = batch.block_first + static_cast<std::size_t>(v) * E;
      r += sums[base + e - 1] - 2.0 * sums[base + e] + sums[base + e + 1];
    }
    r /= V;
    penalty += ring_lambda * r * r;
    if (d_sums == nullptr) continue;
    const double g = 2.0 * ring_lambda * r / V;
    for (std::uint32_t v = 0; v < V; ++v) {
      const std::size_t base = batch.block_first + static_cast<std::size_t>(v) * E;
      (*d_sums)[base + e - 1] += g;
      (*d_sums)[base + e] -= 2.0 * g;
      (*d_sums)[base + e + 1] += g;
    }
  }
  return penalty;
}

std::vector<float> riner_step_field_evaluate(const model::ParameterLayout& l,
                                             const std::vector<double>& params,
                                             const std::vector<float>& positions,
                                             const std::vector<float>& level_weights) {
  const std::size_t n = positions.size() / static_cast<std::size_t>(l.dims);
  std::vector<float> out(n);
  util::parallel_for(n, [&](std::size_t begin, std::size_t end) {
    std::vector<double> features(static_cast<std::size_t>(l.inputs));
    for (std::size_t i = begin; i < end; ++i) {
      double pos[3] = {0, 0, 0};
      for (int d = 0; d < l.dims; ++d) pos[d] = positions[i * l.dims + d];
      hash_grid_encode(l, params.data(), pos, features.data());
      scale_levels(l, level_weights, features.data());
      out[i] = static_cast<float>(mlp_forward(l, params.data(), features.data()));
    }
  });
  return out;
}

}  // namespace riner::ref
