// riner_step.cl: one training step of Riner in three kernels, and the trained field's evaluation.
//   riner_step_forward(n_samples, sample_rays, offsets, rays, segments, levels, level_weights,
//                      params, mlp_offset, seed, step, jitter, mu_dx, cache, cache_stride)
//     one work-item per sample of the batch (batch ray b = sample_rays[i] owns samples
//     offsets[b] .. offsets[b + 1]): mu_dx[i] = mu * dx at the sample, and its encoded features
//     and hidden activations (SAMPLE_CACHE values, value v at cache[v * cache_stride + i]),
//     which the backward pass reads back instead of recomputing them. Per sample rather than per ray so that the work-items of a work-group
//     run in lock step (the SIMD lanes of a CPU, the warps of a GPU).
//   riner_step_loss(n_batch, offsets, mu_dx, rays, sums, rho, weights, elements_per_view, params, alpha_offset,
//                   beta_offset, n_elements, elements, lambda, relative_threshold, data_weight,
//                   block_first, block_views, block_elements, ring_lambda, hold_valid_beta,
//                   invalid_readings, grad, d_sums, loss, scratch)
//     one work-item, over the batch in order (deterministic): each ray's sum of mu dx into
//     sums[b] (in sample order), each ray's loss (ray_sum.cl) and
//     its gradient d_sums[b] with respect to sums[b]; alpha0/beta0 gradients into grad; the
//     -lambda beta^2 term of the batch's elements; and, when ring_lambda > 0, the ring prior on
//     the views x elements block (below). loss[0] = data term, loss[1] = penalties.
//     When relative_threshold > 0, lambda is replaced by
//     data_weight relative_threshold max(m, 1e-3) / 2, m the batch's median ray mismatch
//     (scratch float[n_batch] holds the mismatches): the beta penalty then switches an element
//     off when its rays miss by more than relative_threshold times the batch's typical ray,
//     whatever the object and however far training has come.
//     When hold_valid_beta != 0, beta0 of every element without invalid readings
//     (invalid_readings[e] == 0) gets no gradient: held during the beta warm-up.
//   riner_step_backward(n_lanes, n_batch, offsets, rays, segments, levels, level_weights,
//                       params, grad, lane_stride, mlp_offset, seed, step, jitter, d_sums, cache,
//                       cache_stride)
//     one work-item per lane; lane l takes the batch's rays l, l + n_lanes, ... (interleaved, so
//     lanes get similar work) and back-propagates d_sums[b] * dx through each sample's cached
//     features and activations into grad + lane * lane_stride (lane_stride = 0 with
//     -D ATOMIC_GRADIENTS: one shared gradient).
//   field_evaluate(n, first, nx, ny, nz, voxel, extent, levels, level_weights, params,
//                  mlp_offset, out)
//     one work-item per voxel index first + i of the grid [nz][ny][nx]: mu at its centre.
//
// Ring prior (riner's addition; off when ring_lambda = 0): a detector offset constant over
// views can always be explained by a ring in the image instead, so the data alone cannot decide
// (README, "Rings and the detector response"). The block of the batch holds block_views views
// of the same block_elements adjacent elements, view-major from block_first. For each inner
// element e of the block, r_e = mean over the block's views of the second difference
// sums(v, e - 1) - 2 sums(v, e) + sums(v, e + 1): the view-averaged projection's curvature,
// which a ring in the image makes large and a real object (not rotationally symmetric) does not.
// The prior adds ring_lambda * sum_e r_e^2, so per-element offsets go to alpha.
//
// Buffers: rays uint[n_batch] (ray ids); segments float8[rays] = (start xyz, step xyz, dx,
// count as uint bits) in normalised coordinates (lib/src/model/ray_segments.hpp); rho
// float[rays]; weights float[n_batch] (data-term weight per ray); params/grad float[n_params] as
// lib/src/model/parameter_layout.hpp lays them out; level_weights float[N_LEVELS] (coarse to
// fine, all 1 when every level is on).
// Needs common.cl, hash_grid.cl, mlp.cl, ray_sum.cl (and their -D constants).

// Coarse to fine: level l's features scaled by weights[l] (and so its gradient).
inline void scale_levels(__global const float* weights, float* values) {
  for (int l = 0; l < N_LEVELS; ++l) {
    for (int f = 0; f < N_FEATURES; ++f) values[l * N_FEATURES + f] *= weights[l];
  }
}

inline void segment_sample(float8 s, uint k, float u, float* pos) {
  const float t = (float)k + u;
  pos[0] = s.s0 + t * s.s3;
  pos[1] = s.s1 + t * s.s4;
#if DIMS == 3
  pos[2] = s.s2 + t * s.s5;
#endif
}

// Floats cached per sample between the forward and the backward pass.
#define SAMPLE_CACHE (N_ENCODED + MLP_HIDDEN * MLP_WIDTH)

__kernel void riner_step_forward(const uint n_samples, __global const uint* sample_rays,
                                 __global const uint* offsets, __global const uint* rays, __global const float8* segments,
                                 __constant const GridLevel* levels, __global const float* level_weights,
                                 __global const float* params, const uint mlp_offset, const uint seed,
                                 const uint step, const int jitter, __global float* mu_dx,
                                 __global float* cache, const uint cache_stride) {
  const uint i = get_global_id(0);
  if (i >= n_samples) return;
  const uint b = sample_rays[i];
  const uint ray = rays[b];
  const float8 s = segments[ray];
  const uint k = i - offsets[b];
  float pos[DIMS];
  float features[N_ENCODED];
  float act[MLP_HIDDEN][MLP_WIDTH];
  segment_sample(s, k, jitter ? sample_jitter(seed, step, ray, k) : 0.5f, pos);
  hash_grid_encode(levels, params, pos, features);
  scale_levels(level_weights, features);
  mu_dx[i] = mlp_forward(params + mlp_offset, features, act) * s.s6;
  // Value v of sample i at cache[v * cache_stride + i]: neighbouring work-items store to
  // neighbouring addresses.
  for (int f = 0; f < N_ENCODED; ++f) cache[f * cache_stride + i] = features[f];
  for (int h = 0; h < MLP_HIDDEN; ++h) {
    for (int j = 0; j < MLP_WIDTH; ++j) cache[(N_ENCODED + h * MLP_WIDTH + j) * cache_stride + i] = act[h][j];
  }
}

// The k-th smallest of values[0 .. n) (Hoare's selection; reorders values).
inline float select_kth(__global float* values, uint n, uint k) {
  uint lo = 0;
  uint hi = n - 1;
  while (lo < hi) {
    const float pivot = values[(lo + hi) / 2];
    uint i = lo;
    uint j = hi;
    while (i <= j) {
      while (values[i] < pivot) ++i;
      while (values[j] > pivot) --j;
      if (i <= j) {
        const float t = values[i];
        values[i] = values[j];
        values[j] = t;
        ++i;
        if (j == 0) break;
        --j;
      }
    }
    if (k <= j) {
      hi = j;
    } else if (k >= i) {
      lo = i;
    } else {
      break;
    }
  }
  return values[k];
}

__kernel void riner_step_loss(const uint n_batch, __global const uint* offsets, __global const float* mu_dx,
                              __global const uint* rays, __global float* sums,
                              __global const float* rho, __global const float* weights,
                              const uint elements_per_view, __global const float* params,
                              const uint alpha_offset, const uint beta_offset, const uint n_elements,
                              __global const uint* elements, const float lambda, const float relative_threshold,
                              const float data_weight, const uint block_first, const uint block_views,
                              const uint block_elements, const float ring_lambda,
                              const uint hold_valid_beta, __global const uint* invalid_readings,
                              __global float* grad,
                              __global float* d_sums, __global float* loss, __global float* scratch) {
  if (get_global_id(0) != 0) return;
  for (uint b = 0; b < n_batch; ++b) {
    float sum = 0.0f;
    for (uint i = offsets[b]; i < offsets[b + 1]; ++i) sum += mu_dx[i];
    sums[b] = sum;
  }
  float penalty_weight = lambda;
  if (relative_threshold > 0.0f && n_batch > 0) {
    for (uint b = 0; b < n_batch; ++b) {
      const uint ray = rays[b];
      scratch[b] = ray_mismatch(sums[b], params[alpha_offset + ray % elements_per_view], rho[ray]);
    }
    const float median = select_kth(scratch, n_batch, (n_batch - 1) / 2);
    penalty_weight = 0.5f * data_weight * relative_threshold * fmax(median, 1e-3f);
  }
  float data = 0.0f;
  for (uint b = 0; b < n_batch; ++b) {
    const uint ray = rays[b];
    const uint e = ray % elements_per_view;
    float d_sum;
    float d_alpha0;
    float d_beta0;
    data += ray_loss(sums[b], params[alpha_offset + e], params[beta_offset + e], rho[ray], weights[b], &d_sum,
                     &d_alpha0, &d_beta0);
    d_sums[b] = d_sum;
    GRAD_ADD(&grad[alpha_offset + e], d_alpha0);
    if (!hold_valid_beta || invalid_readings[e] != 0) GRAD_ADD(&grad[beta_offset + e], d_beta0);
  }
  float penalty = 0.0f;
  for (uint i = 0; i < n_elements; ++i) {
    float d_beta0;
    penalty += beta_penalty(params[beta_offset + elements[i]], penalty_weight, &d_beta0);
    if (!hold_valid_beta || invalid_readings[elements[i]] != 0)
      GRAD_ADD(&grad[beta_offset + elements[i]], d_beta0);
  }
  if (ring_lambda > 0.0f && block_views > 0 && block_elements >= 3) {
    // r_e for the inner elements e = 1 .. E - 2, then its gradient on every block sum.
    const uint E = block_elements;
    for (uint e = 1; e + 1 < E; ++e) {
      float r = 0.0f;
      for (uint v = 0; v < block_views; ++v) {
        const uint base = block_first + v * E;
        r += sums[base + e - 1] - 2.0f * sums[base + e] + sums[base + e + 1];
      }
      r /= (float)block_views;
      penalty += ring_lambda * r * r;
      const float g = 2.0f * ring_lambda * r / (float)block_views;
      for (uint v = 0; v < block_views; ++v) {
        const uint base = block_first + v * E;
        d_sums[base + e - 1] += g;
        d_sums[base + e] -= 2.0f * g;
        d_sums[base + e + 1] += g;
      }
    }
  }
  loss[0] = data;
  loss[1] = penalty;
}

__kernel void riner_step_backward(const uint n_lanes, const uint n_batch, __global const uint* offsets,
                                  __global const uint* rays, __global const float8* segments,
                                  __constant const GridLevel* levels, __global const float* level_weights,
                                  __global const float* params, __global float* grad_all, const uint lane_stride,
                                  const uint mlp_offset, const uint seed, const uint step, const int jitter,
                                  __global const float* d_sums, __global const float* cache,
                                  const uint cache_stride) {
  const uint lane = get_global_id(0);
  if (lane >= n_lanes) return;
  __global float* grad = grad_all + lane * lane_stride;
  __global const float* mlp = params + mlp_offset;
  float features[N_ENCODED];
  float act[MLP_HIDDEN][MLP_WIDTH];
  float d_features[N_ENCODED];
  float pos[DIMS];
  for (uint b = lane; b < n_batch; b += n_lanes) {
    const uint ray = rays[b];
    const float8 s = segments[ray];
    const float d_mu = d_sums[b] * s.s6;
    if (d_mu == 0.0f) continue;
    for (uint i = offsets[b]; i < offsets[b + 1]; ++i) {
      const uint k = i - offsets[b];
      for (int f = 0; f < N_ENCODED; ++f) features[f] = cache[f * cache_stride + i];
      for (int h = 0; h < MLP_HIDDEN; ++h) {
        for (int j = 0; j < MLP_WIDTH; ++j) act[h][j] = cache[(N_ENCODED + h * MLP_WIDTH + j) * cache_stride + i];
      }
      mlp_backward(mlp, grad + mlp_offset, features, act, d_mu, d_features);
      scale_levels(level_weights, d_features);
      segment_sample(s, k, jitter ? sample_jitter(seed, step, ray, k) : 0.5f, pos);
      hash_grid_scatter(levels, grad, pos, d_features);
    }
  }
}

__kernel void field_evaluate(const uint n, const uint first, const uint nx, const uint ny, const uint nz,
                             const float voxel, const float extent, __constant const GridLevel* levels,
                             __global const float* level_weights, __global const float* params,
                             const uint mlp_offset, __global float* out) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  const uint index = first + i;
  const uint k = index % nx;
  const uint row = (index / nx) % ny;
  const uint slice = index / (nx * ny);
  // Voxel centre (README, "Geometry convention") in the encoding's normalised cube.
  float pos[3];
  pos[0] = ((float)k - 0.5f * (float)(nx - 1)) * voxel / extent + 0.5f;
  pos[1] = (0.5f * (float)(ny - 1) - (float)row) * voxel / extent + 0.5f;
  pos[2] = ((float)slice - 0.5f * (float)(nz - 1)) * voxel / extent + 0.5f;
  float features[N_ENCODED];
  float act[MLP_HIDDEN][MLP_WIDTH];
  hash_grid_encode(levels, params, pos, features);
  scale_levels(level_weights, features);
  out[index] = mlp_forward(params + mlp_offset, features, act);
}
