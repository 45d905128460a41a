// adam.cl: one Adam step over the flat parameter buffer, as PyTorch computes it.
//   adam_step(p, params, m, v, grad, partials)
//     one work-item per ADAM_LANES consecutive parameters (launch ceil(p.n / ADAM_LANES)); the
//     gradient of parameter i < p.n is grad[i] (zeroed for the next step)
//     plus, for p.partial_offset <= i < p.partial_offset + p.partial_count, the p.n_partials
//     partial sums partials[q * partial_count + i - partial_offset] added in order q = 0, 1, ...
//     (the split-K slices of the MLP's weight gradient, mlp_gradient.cl: deterministic).
//     step_size = lr / (1 - beta1^t); inv_sqrt_bias2 = 1 / sqrt(1 - beta2^t); parameters from
//     alpha_offset on (alpha0) use alpha_step_size, from beta_offset on (beta0)
//     beta_step_size. Parameters i < sparse_below with a zero gradient are skipped (their value
//     and moments stay); all others are updated every step.
// Eight lanes in explicit vectors: the branch on a zero gradient kept the compiler from
// vectorising one parameter per work-item, and on a CPU a volume's step spent 40% of its time
// here, scalar (docs/history/RESULTS.md, issue 34). A group that meets the split-K range or
// the end of the buffer takes the scalar path, the same arithmetic.
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

#define ADAM_LANES 8

RINER_INLINE void adam_one(const AdamParams* p, uint i, __global float* params, __global float* m,
                           __global float* v, __global float* grad,
                           __global const float* partials) {
  float g = grad[i];
  const uint k = i - p->partial_offset;  // wraps above partial_count when i < partial_offset
  if (k < p->partial_count) {
    for (uint q = 0; q < p->n_partials; ++q) g += partials[q * p->partial_count + k];
  }
  if (i < p->sparse_below && g == 0.0f) return;  // grad[i] is 0 already
  grad[i] = 0.0f;
  const float m_new = p->beta1 * m[i] + (1.0f - p->beta1) * g;
  const float v_new = p->beta2 * v[i] + (1.0f - p->beta2) * g * g;
  m[i] = m_new;
  v[i] = v_new;
  const float size = i < p->alpha_offset ? p->step_size
                     : (i < p->beta_offset ? p->alpha_step_size : p->beta_step_size);
  params[i] -= size * m_new / (sqrt(v_new) * p->inv_sqrt_bias2 + p->epsilon);
}

__kernel void adam_step(const AdamParams p, __global float* params, __global float* m,
                        __global float* v, __global float* grad, __global const float* partials) {
  const uint group = get_global_id(0);
  const uint groups = (p.n + ADAM_LANES - 1) / ADAM_LANES;
  if (group >= groups) {
    // The parameters with split-K partial sums, one a work-item after the groups: eight a
    // work-item left a GPU's 264 partials of each MLP weight to one thread's loop (0.12 ms of
    // an H200's 0.62 ms step).
    const uint k = group - groups;
    if (k < p.partial_count) adam_one(&p, p.partial_offset + k, params, m, v, grad, partials);
    return;
  }
  const uint first = group * ADAM_LANES;
  const uint end = first + ADAM_LANES;
  const int meets_partials =
      p.partial_count > 0 && first < p.partial_offset + p.partial_count && end > p.partial_offset;
  if (end > p.n || meets_partials) {
    const uint last = min(end, p.n);
    for (uint i = first; i < last; ++i) {
      if (i - p.partial_offset >= p.partial_count) adam_one(&p, i, params, m, v, grad, partials);
    }
    return;
  }
  const float8 g = vload8(group, grad);
  const int8 index = (int8)((int)first) + (int8)(0, 1, 2, 3, 4, 5, 6, 7);
  // Lanes below sparse_below with a zero gradient keep their value and moments (lazy Adam).
  const int8 lazy = (index < (int8)((int)p.sparse_below)) & (g == (float8)(0.0f));
  if (all(lazy)) return;
  vstore8((float8)(0.0f), group, grad);
  const float8 m_old = vload8(group, m);
  const float8 v_old = vload8(group, v);
  const float8 m_new = p.beta1 * m_old + (1.0f - p.beta1) * g;
  const float8 v_new = p.beta2 * v_old + (1.0f - p.beta2) * g * g;
  const float8 size =
      select(select((float8)(p.beta_step_size), (float8)(p.alpha_step_size),
                    index < (int8)((int)p.beta_offset)),
             (float8)(p.step_size), index < (int8)((int)p.alpha_offset));
  const float8 old = vload8(group, params);
  const float8 moved = old - size * m_new / (sqrt(v_new) * p.inv_sqrt_bias2 + p.epsilon);
  vstore8(select(m_new, m_old, lazy), group, m);
  vstore8(select(v_new, v_old, lazy), group, v);
  vstore8(select(moved, old, lazy), group, params);
}
