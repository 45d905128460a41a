// adam.cl: one Adam step over the flat parameter buffer, as PyTorch computes it.
//   adam_step(n, step_size, alpha_offset, alpha_step_size, beta_offset, beta_step_size, beta1,
//             beta2, inv_sqrt_bias2, epsilon, params, m, v, grad, partial_offset,
//             partial_count, n_partials, partials)
//     one work-item per parameter i; its gradient is grad[i] (zeroed for the next step) plus,
//     for partial_offset <= i < partial_offset + partial_count, the n_partials partial sums
//     partials[p * partial_count + i - partial_offset] added in order p = 0, 1, ... (the
//     split-K slices of the MLP's weight gradient, mlp_gradient.cl: deterministic).
//     step_size = lr / (1 - beta1^t); inv_sqrt_bias2 = 1 / sqrt(1 - beta2^t); parameters from
//     alpha_offset on (alpha0) use alpha_step_size, from beta_offset on (beta0)
//     beta_step_size. Every parameter is updated every step (no skipping of zero gradients).
// No -D constants. CPU twin: lib/src/reference/adam_ref.cpp.

__kernel void adam_step(const uint n, const float step_size, const uint alpha_offset,
                        const float alpha_step_size, const uint beta_offset, const float beta_step_size,
                        const float beta1, const float beta2, const float inv_sqrt_bias2,
                        const float epsilon, __global float* params, __global float* m, __global float* v,
                        __global float* grad, const uint partial_offset, const uint partial_count,
                        const uint n_partials, __global const float* partials) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  float g = grad[i];
  grad[i] = 0.0f;
  const uint k = i - partial_offset;  // wraps above partial_count when i < partial_offset
  if (k < partial_count) {
    for (uint p = 0; p < n_partials; ++p) g += partials[p * partial_count + k];
  }
  const float m_new = beta1 * m[i] + (1.0f - beta1) * g;
  const float v_new = beta2 * v[i] + (1.0f - beta2) * g * g;
  m[i] = m_new;
  v[i] = v_new;
  const float size = i < alpha_offset ? step_size : (i < beta_offset ? alpha_step_size : beta_step_size);
  params[i] -= size * m_new / (sqrt(v_new) * inv_sqrt_bias2 + epsilon);
}
