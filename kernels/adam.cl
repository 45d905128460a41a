// adam.cl: one Adam step over the flat parameter buffer, as PyTorch computes it.
//   adam_step(p, params, m, v, grad, partials)
//     one work-item per parameter i < p.n; its gradient is grad[i] (zeroed for the next step)
//     plus, for p.partial_offset <= i < p.partial_offset + p.partial_count, the p.n_partials
//     partial sums partials[q * partial_count + i - partial_offset] added in order q = 0, 1, ...
//     (the split-K slices of the MLP's weight gradient, mlp_gradient.cl: deterministic).
//     step_size = lr / (1 - beta1^t); inv_sqrt_bias2 = 1 / sqrt(1 - beta2^t); parameters from
//     alpha_offset on (alpha0) use alpha_step_size, from beta_offset on (beta0)
//     beta_step_size. Parameters i < sparse_below with a zero gradient are skipped (their value
//     and moments stay); all others are updated every step.
// No -D constants. CPU twin: lib/src/reference/adam_ref.cpp.

// Host mirror: ops::AdamParams (lib/src/ops/adam.hpp), 14 four-byte members.
typedef struct {
  uint n;
  float step_size;
  uint alpha_offset;
  float alpha_step_size;
  uint beta_offset;
  float beta_step_size;
  float beta1;
  float beta2;
  float inv_sqrt_bias2;
  float epsilon;
  uint partial_offset;
  uint partial_count;
  uint n_partials;
  uint sparse_below;
} AdamParams;

__kernel void adam_step(const AdamParams p, __global float* params, __global float* m,
                        __global float* v, __global float* grad, __global const float* partials) {
  const uint i = get_global_id(0);
  if (i >= p.n) return;
  float g = grad[i];
  const uint k = i - p.partial_offset;  // wraps above partial_count when i < partial_offset
  if (k < p.partial_count) {
    for (uint q = 0; q < p.n_partials; ++q) g += partials[q * p.partial_count + k];
  }
  if (i < p.sparse_below && g == 0.0f) return;  // grad[i] is 0 already
  grad[i] = 0.0f;
  const float m_new = p.beta1 * m[i] + (1.0f - p.beta1) * g;
  const float v_new = p.beta2 * v[i] + (1.0f - p.beta2) * g * g;
  m[i] = m_new;
  v[i] = v_new;
  const float size =
      i < p.alpha_offset ? p.step_size : (i < p.beta_offset ? p.alpha_step_size : p.beta_step_size);
  params[i] -= size * m_new / (sqrt(v_new) * p.inv_sqrt_bias2 + p.epsilon);
}
