// riner_step_lanes.cl: the training step's per-sample kernels in the CPU's shape (the CPU
// plan's). PoCL vectorises a work-group's work-items only where their loads are contiguous, so
// riner_step_forward and riner_step_backward run one sample per work-item with the MLP in
// float16 across its units: the grid's lookups, mlp_deltas' horizontal sums and the ~100
// strided cache accesses of each sample stay scalar. Here a work-item takes 16 consecutive
// samples, one per lane of float16 vectors: the MLP's weights are broadcast scalars, each cache
// row is read or written as one vector, and only the grid's lookups gather.
//   riner_step_forward_lanes(p, batch, levels, params, mu_dx, cache)
//   riner_step_backward_lanes(p, batch, levels, params, d_sums, cache)
//     work-item w: samples 16 w .. 16 w + 15. Lanes past n_samples repeat the last sample and
//     write into the rows' padding: the host keeps cache_stride (and mu_dx) a multiple of 16
//     that holds them. The backward writes CACHE_DIN and CACHE_POS for hash_grid_gradient.cl
//     (plans without ATOMIC_GRADIENTS).
// Each lane computes the terms of the per-sample kernels in their order (sum16's tree
// included), so both shapes give the same values.
// Needs common.cl, hash_grid.cl, mlp.cl, sample_cache.cl.

#define STEP_LANES 16

// The sums of sum16 (mlp.cl) over 16 vectors' k-th lanes: t[k] is overwritten.
RINER_INLINE float16 tree_sum16(float16* t) {
  RINER_UNROLL
  for (int k = 0; k < 8; ++k) t[k] = t[k] + t[k + 8];
  RINER_UNROLL
  for (int k = 0; k < 4; ++k) t[k] = t[k] + t[k + 4];
  RINER_UNROLL
  for (int k = 0; k < 2; ++k) t[k] = t[k] + t[k + 2];
  return t[0] + t[1];
}

// Lane k's sample min(first + k, n_samples - 1): its position, the ray's dx and its batch ray.
RINER_INLINE void lanes_samples(const StepParams* p, __global const uint* batch, uint first,
                                float16* pos, float16* dx, uint* rays) {
  __global const uint* offsets = batch + p->offsets_at;
  uint b = batch_ray_of(offsets, p->n_batch, first);
  float at[DIMS][STEP_LANES];
  float step[STEP_LANES];
  for (int k = 0; k < STEP_LANES; ++k) {
    const uint i = min(first + k, p->n_samples - 1);
    while (b + 1 < p->n_batch && offsets[b + 1] <= i) ++b;
    const uint ray = batch[p->rays_at + b];
    const float8 s = batch_segment(batch, p, b);
    const uint j = i - offsets[b];
    float q[DIMS];
    segment_sample(s, j, p->jitter ? sample_jitter(p->seed, p->step, ray, j) : 0.5f, q);
    RINER_UNROLL
    for (int d = 0; d < DIMS; ++d) at[d][k] = q[d];
    step[k] = s.s6;
    rays[k] = b;
  }
  RINER_UNROLL
  for (int d = 0; d < DIMS; ++d) pos[d] = vload16(0, at[d]);
  *dx = vload16(0, step);
}

// Coarse to fine (scale_levels in sample_cache.cl) for 16 samples.
RINER_INLINE void scale_levels_lanes(__global const float* weights, float16* values) {
  RINER_UNROLL
  for (int l = 0; l < N_LEVELS; ++l) {
    RINER_UNROLL
    for (int f = 0; f < N_FEATURES; ++f) values[l * N_FEATURES + f] *= weights[l];
  }
}

// mlp_forward (mlp.cl) for 16 samples.
RINER_INLINE float16 mlp_forward_lanes(__global const float* w, const float16* in,
                                       float16 act[MLP_HIDDEN][MLP_WIDTH]) {
  for (int j = 0; j < MLP_WIDTH; ++j) {
    float16 h = w[MLP_B_IN + j];
    RINER_UNROLL
    for (int i = 0; i < MLP_INPUTS; ++i)
      h = mad(in[i], (float16)(w[MLP_W_IN + i * MLP_WIDTH + j]), h);
    act[0][j] = fmax(h, 0.0f);
  }
  for (int layer = 1; layer < MLP_HIDDEN; ++layer) {
    for (int j = 0; j < MLP_WIDTH; ++j) {
      float16 h = w[MLP_B_HIDDEN(layer) + j];
      for (int i = 0; i < MLP_WIDTH; ++i)
        h = mad(act[layer - 1][i], (float16)(w[MLP_W_HIDDEN(layer) + i * MLP_WIDTH + j]), h);
      act[layer][j] = fmax(h, 0.0f);
    }
  }
  float16 out = w[MLP_B_OUT];
  RINER_UNROLL
  for (int v = 0; v < MLP_V; ++v) {
    float16 t[16];
    RINER_UNROLL
    for (int k = 0; k < 16; ++k) t[k] = act[MLP_HIDDEN - 1][16 * v + k] * w[MLP_W_OUT + 16 * v + k];
    out += tree_sum16(t);
  }
  return out;
}

// sum16 of mad(row[j], d[j]) over the MLP's units as mlp_deltas forms it, for 16 samples.
RINER_INLINE float16 row_dot_lanes(__global const float* row, const float16* d) {
  float16 t[16];
  RINER_UNROLL
  for (int k = 0; k < 16; ++k) t[k] = 0.0f;
  RINER_UNROLL
  for (int v = 0; v < MLP_V; ++v) {
    RINER_UNROLL
    for (int k = 0; k < 16; ++k) t[k] = mad((float16)(row[16 * v + k]), d[16 * v + k], t[k]);
  }
  return tree_sum16(t);
}

// mlp_deltas (mlp.cl) for 16 samples.
RINER_INLINE void mlp_deltas_lanes(__global const float* w, float16 act[MLP_HIDDEN][MLP_WIDTH],
                                   const float16 d_out, float16 delta[MLP_HIDDEN][MLP_WIDTH],
                                   float16* d_in) {
  for (int j = 0; j < MLP_WIDTH; ++j) {
    delta[MLP_HIDDEN - 1][j] =
        select((float16)(0.0f), d_out * w[MLP_W_OUT + j], act[MLP_HIDDEN - 1][j] > 0.0f);
  }
  for (int layer = MLP_HIDDEN - 1; layer >= 1; --layer) {
    for (int i = 0; i < MLP_WIDTH; ++i) {
      const float16 next = row_dot_lanes(w + MLP_W_HIDDEN(layer) + i * MLP_WIDTH, delta[layer]);
      delta[layer - 1][i] = select((float16)(0.0f), next, act[layer - 1][i] > 0.0f);
    }
  }
  RINER_UNROLL
  for (int i = 0; i < MLP_INPUTS; ++i)
    d_in[i] = row_dot_lanes(w + MLP_W_IN + i * MLP_WIDTH, delta[0]);
}

__kernel void riner_step_forward_lanes(const StepParams p, __global const uint* batch,
                                       __constant const GridLevel* levels,
                                       __global const float* params, __global float* mu_dx,
                                       __global float* cache) {
  const uint first = get_global_id(0) * STEP_LANES;
  if (first >= p.n_samples) return;
  float16 pos[DIMS];
  float16 dx;
  uint rays[STEP_LANES];
  lanes_samples(&p, batch, first, pos, &dx, rays);
  float16 features[N_ENCODED];
  float16 act[MLP_HIDDEN][MLP_WIDTH];
  hash_grid_encode_lanes(levels, params, pos, features);
  scale_levels_lanes((__global const float*)(batch + p.level_weights_at), features);
  vstore16(mlp_forward_lanes(params + p.mlp_offset, features, act) * dx, 0, mu_dx + first);
  __global float* rows = cache + first;
  const uint stride = p.cache_stride;
  RINER_UNROLL
  for (int f = 0; f < N_ENCODED; ++f)
    vstore16(features[f], 0, rows + (CACHE_FEATURES + f) * stride);
  for (int h = 0; h < MLP_HIDDEN; ++h) {
    for (int j = 0; j < MLP_WIDTH; ++j) vstore16(act[h][j], 0, rows + (CACHE_ACT(h) + j) * stride);
  }
}

__kernel void riner_step_backward_lanes(const StepParams p, __global const uint* batch,
                                        __constant const GridLevel* levels,
                                        __global const float* params, __global const float* d_sums,
                                        __global float* cache) {
  const uint first = get_global_id(0) * STEP_LANES;
  if (first >= p.n_samples) return;
  float16 pos[DIMS];
  float16 dx;
  uint rays[STEP_LANES];
  lanes_samples(&p, batch, first, pos, &dx, rays);
  const float16 d_mu = gather16(d_sums, rays) * dx;
  __global float* rows = cache + first;
  const uint stride = p.cache_stride;
  float16 act[MLP_HIDDEN][MLP_WIDTH];
  for (int h = 0; h < MLP_HIDDEN; ++h) {
    for (int j = 0; j < MLP_WIDTH; ++j) act[h][j] = vload16(0, rows + (CACHE_ACT(h) + j) * stride);
  }
  float16 delta[MLP_HIDDEN][MLP_WIDTH];
  float16 d_features[N_ENCODED];
  mlp_deltas_lanes(params + p.mlp_offset, act, d_mu, delta, d_features);
  // The last hidden layer's deltas are formed again where they are summed (mlp_gradient.cl's
  // last_deltas8, from the activations and d_mu): 64 rows a sample not stored.
  for (int h = 0; h + 1 < MLP_HIDDEN; ++h) {
    for (int j = 0; j < MLP_WIDTH; ++j)
      vstore16(delta[h][j], 0, rows + (CACHE_DELTA(h) + j) * stride);
  }
  vstore16(d_mu, 0, rows + CACHE_DMU * stride);
  scale_levels_lanes((__global const float*)(batch + p.level_weights_at), d_features);
  RINER_UNROLL
  for (int f = 0; f < N_ENCODED; ++f) vstore16(d_features[f], 0, rows + (CACHE_DIN + f) * stride);
  RINER_UNROLL
  for (int d = 0; d < DIMS; ++d) vstore16(pos[d], 0, rows + (CACHE_POS + d) * stride);
}
