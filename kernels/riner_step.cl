// riner_step.cl: one training step of Riner (METHOD.md section 2), sample-parallel, and the
// trained field's evaluation. The step runs as
//   riner_step_forward    one work-item per sample of the batch
//   riner_step_loss       one work-group: ray sums, losses, alpha0/beta0 gradients, penalties
//   riner_step_backward   one work-item per sample
// then the weight gradients are reduced by mlp_gradient.cl, the grid's by atomics here
// (-D ATOMIC_GRADIENTS) or by ownership in hash_grid_gradient.cl, and adam.cl applies them.
//
//   riner_step_forward(p, batch, levels, params, mu_dx, cache)
//     sample i of batch ray b (batch_ray_of): mu_dx[i] = mu * dx at the sample; its features
//     and activations into the cache (sample_cache.cl).
//   riner_step_loss(p, batch, mu_dx, params, invalid_readings, response_slots, grad, sums,
//                   d_sums, ray_grads, history, scratch)
//     one work-group of any size (the plan's): work-items take rays b = lid, lid + size, ...:
//     sums[b] = sum of mu dx over the ray's samples (in sample order), the ray's loss
//     (ray_sum.cl), d_sums[b] and its alpha0/beta0 gradients; then elements i = lid, ...
//     of the batch's distinct elements: their rays' gradients in ascending ray order plus the
//     -lambda beta^2 term into grad (each element's entries are written by one work-item:
//     deterministic, no atomics). A reading's alpha0 and beta0 are its response slot's
//     (response_slot: the element's, or for an element whose response changes part-way its
//     segment's, lib/src/model/response_map.hpp); an element's slots take their rays' gradients
//     and a penalty each when the batch holds one of their rays; invalid_readings is per
//     response slot. history[2 * p.history_slot] = data term, [2 * p.history_slot + 1] =
//     penalties, summed by a fixed tree. When relative_beta_threshold > 0, lambda is raised to
//     data_weight relative_beta_threshold max(m, 1e-3) / 2 where that is larger, m the batch's
//     median ray mismatch, for elements whose readings are all finite (an element with a
//     non-finite reading keeps lambda) (scratch float[n_batch]). When hold_valid_beta != 0,
//     beta0 of every element without invalid readings gets no gradient (the beta warm-up).
//   riner_step_backward(p, batch, levels, params, d_sums, cache, grad)
//     sample i: d_mu = d_sums[b] dx through the MLP (mlp_deltas); deltas and d_mu into the
//     cache for mlp_gradient.cl; the features' gradient into the grid: with
//     -D ATOMIC_GRADIENTS by float atomics into grad (common.cl picks the device's fastest),
//     otherwise into the cache (CACHE_DIN, CACHE_POS) for hash_grid_gradient.cl.
//   riner_step_field_evaluate(g, levels, level_weights, params, out)
//     one work-item per voxel index g.first + i (i < g.n) of the grid [nz][ny][nx]: mu at its
//     centre.
//
// Ring prior (riner's addition; off when ring_lambda = 0): a detector offset constant over
// views can always be explained by a ring in the image instead (docs/method.md, "Rings and the
// detector response"). The block of the batch holds block_views views of the same
// block_elements adjacent elements, view-major from block_first. For each inner element e,
// r_e = mean over the block's views of sums(v, e - 1) - 2 sums(v, e) + sums(v, e + 1), and the
// prior adds ring_lambda * sum_e r_e^2, so per-element offsets go to alpha.
//
// Buffers: batch uint[] packed as sample_cache.cl describes (the rays' segments and readings
// included), StepParams p says where; params/grad float[n_params]
// as lib/src/model/parameter_layout.hpp lays them out; sums, d_sums float[n_batch], ray_grads
// float2[n_batch].
// Needs common.cl, hash_grid.cl, mlp.cl, ray_sum.cl, sample_cache.cl (and their -D constants).

__kernel void riner_step_forward(const StepParams p, __global const uint* batch,
                                 __constant const GridLevel* levels, __global const float* params,
                                 __global float* mu_dx, __global float* cache) {
  const uint i = get_global_id(0);
  if (i >= p.n_samples) return;
  __global const uint* offsets = batch + p.offsets_at;
  const uint b = batch_ray_of(offsets, p.n_batch, i);
  const uint ray = batch[p.rays_at + b];
  const float8 s = batch_segment(batch, &p, b);
  const uint k = i - offsets[b];
  float pos[DIMS];
  float features[N_ENCODED];
  float act[MLP_HIDDEN][MLP_WIDTH];
  segment_sample(s, k, p.jitter ? sample_jitter(p.seed, p.step, ray, k) : 0.5f, pos);
  hash_grid_encode(levels, params, pos, features);
  scale_levels((__global const float*)(batch + p.level_weights_at), features);
  mu_dx[i] = mlp_forward(params + p.mlp_offset, features, act) * s.s6;
  const uint stride = p.cache_stride;
  RINER_UNROLL
  for (int f = 0; f < N_ENCODED; ++f) cache[(CACHE_FEATURES + f) * stride + i] = features[f];
  RINER_UNROLL
  for (int h = 0; h < MLP_HIDDEN; ++h) {
    RINER_UNROLL
    for (int j = 0; j < MLP_WIDTH; ++j) cache[(CACHE_ACT(h) + j) * stride + i] = act[h][j];
  }
}

#define RESPONSE_VIEW_TABLE 0x80000000u

// The response slot of a reading (lib/src/model/response_map.hpp lays the table out).
RINER_INLINE uint response_slot(__global const uint* slots, uint ray, uint elements_per_view) {
  const uint s = slots[ray % elements_per_view];
  if (!(s & RESPONSE_VIEW_TABLE)) return s;
  const uint o = s & ~RESPONSE_VIEW_TABLE;
  return slots[o + 1 + slots[o] + ray / elements_per_view];
}

// values[b]'s place in the sorted order, NaNs after every number, ties by index: exactly one b
// has each rank.
RINER_INLINE uint stable_rank(__global const float* values, uint n, uint b) {
  const float v = values[b];
  const int v_nan = isnan(v);
  uint rank = 0;
  for (uint j = 0; j < n; ++j) {
    const float w = values[j];
    const int w_nan = isnan(w);
    const int before = (!w_nan && (v_nan || w < v)) || ((w == v || (w_nan && v_nan)) && j < b);
    rank += before ? 1u : 0u;
  }
  return rank;
}

// The k-th smallest of values[0 .. n) (Hoare's selection; reorders values).
RINER_INLINE float select_kth(__global float* values, uint n, uint k) {
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

// The work-group's sum of value (every work-item calls it); the same tree every time.
RINER_INLINE float group_sum(float value, __local float* scratch) {
  const uint lid = get_local_id(0);
  const uint n = get_local_size(0);
  scratch[lid] = value;
  barrier(CLK_LOCAL_MEM_FENCE);
  for (uint span = 1; span < n; span *= 2) {
    if (lid % (2 * span) == 0 && lid + span < n) scratch[lid] += scratch[lid + span];
    barrier(CLK_LOCAL_MEM_FENCE);
  }
  const float total = scratch[0];
  barrier(CLK_LOCAL_MEM_FENCE);
  return total;
}

// The ring prior on the batch's views x elements block: its value; its gradient into d_sums.
RINER_INLINE float ring_prior(const StepParams* p, __global const float* sums,
                              __global float* d_sums) {
  if (p->ring_lambda <= 0.0f || p->block_views == 0 || p->block_elements < 3) return 0.0f;
  const uint E = p->block_elements;
  float penalty = 0.0f;
  for (uint e = 1; e + 1 < E; ++e) {
    float r = 0.0f;
    for (uint v = 0; v < p->block_views; ++v) {
      const uint base = p->block_first + v * E;
      r += sums[base + e - 1] - 2.0f * sums[base + e] + sums[base + e + 1];
    }
    r /= (float)p->block_views;
    penalty += p->ring_lambda * r * r;
    const float g = 2.0f * p->ring_lambda * r / (float)p->block_views;
    for (uint v = 0; v < p->block_views; ++v) {
      const uint base = p->block_first + v * E;
      d_sums[base + e - 1] += g;
      d_sums[base + e] -= 2.0f * g;
      d_sums[base + e + 1] += g;
    }
  }
  return penalty;
}

__kernel void riner_step_loss(const StepParams p, __global const uint* batch,
                              __global const float* mu_dx, __global const float* params,
                              __global const uint* invalid_readings,
                              __global const uint* response_slots, __global float* grad,
                              __global float* sums, __global float* d_sums,
                              __global float2* ray_grads, __global float* history,
                              __global float* scratch, __local float* reduce) {
  const uint lid = get_local_id(0);
  const uint size = get_local_size(0);
  __global const uint* offsets = batch + p.offsets_at;
  for (uint b = lid; b < p.n_batch; b += size) {
    float sum = 0.0f;
    for (uint i = offsets[b]; i < offsets[b + 1]; ++i) sum += mu_dx[i];
    sums[b] = sum;
  }
  barrier(CLK_GLOBAL_MEM_FENCE | CLK_LOCAL_MEM_FENCE);
  // beta's threshold relative to the batch's median ray mismatch. The barriers stay outside
  // the branches: inside one, PoCL 3.1 let the ranking read scratch before the group's other
  // work-items had written it (the cross-check's gpu plan on a 70-ray batch).
  const bool relative = p.relative_beta_threshold > 0.0f && p.n_batch > 0;
  if (relative) {
    for (uint b = lid; b < p.n_batch; b += size) {
      const uint ray = batch[p.rays_at + b];
      const uint slot = response_slot(response_slots, ray, p.elements_per_view);
      scratch[b] = ray_mismatch(sums[b], params[p.alpha_offset + slot], batch_rho(batch, &p, b),
                                p.starved_floor);
    }
  }
  if (lid == 0) reduce[0] = 0.0f;  // stays 0 only if NaNs leave no rank k
  barrier(CLK_GLOBAL_MEM_FENCE | CLK_LOCAL_MEM_FENCE);
  const uint k_median = p.n_batch > 0 ? (p.n_batch - 1) / 2 : 0;
  if (relative && size == 1) {
    reduce[0] = select_kth(scratch, p.n_batch, k_median);
  } else if (relative) {
    // One work-item's quickselect over a GPU's batch took half of a step (0.29 of 0.62 ms on
    // an H200): each work-item ranks its own rays instead, and the one ranked k writes.
    for (uint b = lid; b < p.n_batch; b += size) {
      if (stable_rank(scratch, p.n_batch, b) == k_median) reduce[0] = scratch[b];
    }
  }
  barrier(CLK_LOCAL_MEM_FENCE);
  const float penalty_weight =
      relative ? fmax(p.lambda, 0.5f * p.data_weight * p.relative_beta_threshold *
                                    fmax(reduce[0], 1e-3f))
               : p.lambda;
  barrier(CLK_LOCAL_MEM_FENCE);
  float data = 0.0f;
  for (uint b = lid; b < p.n_batch; b += size) {
    const uint slot = response_slot(response_slots, batch[p.rays_at + b], p.elements_per_view);
    float d_sum;
    float d_alpha0;
    float d_beta0;
    data += ray_loss(sums[b], params[p.alpha_offset + slot], params[p.beta_offset + slot],
                     batch_rho(batch, &p, b), as_float(batch[p.weights_at + b]), p.starved_floor,
                     &d_sum, &d_alpha0, &d_beta0);
    d_sums[b] = d_sum;
    ray_grads[b] = (float2)(d_alpha0, d_beta0);
  }
  barrier(CLK_GLOBAL_MEM_FENCE | CLK_LOCAL_MEM_FENCE);
  float penalty = 0.0f;
  if (lid == 0) penalty = ring_prior(&p, sums, d_sums);
  __global const uint* starts = batch + p.element_rays_at;
  __global const uint* element_rays = starts + p.n_elements + 1;
  for (uint i = lid; i < p.n_elements; i += size) {
    const uint e = batch[p.elements_at + i];
    const uint entry = response_slots[e];
    const uint changing = entry & RESPONSE_VIEW_TABLE;
    const uint o = entry & ~RESPONSE_VIEW_TABLE;
    const uint n_slots = changing ? response_slots[o] : 1;
    for (uint k = 0; k < n_slots; ++k) {
      const uint slot = changing ? response_slots[o + 1 + k] : entry;
      float2 g = (float2)(0.0f);
      uint rays = 0;
      for (uint j = starts[i]; j < starts[i + 1]; ++j) {
        const uint b = element_rays[j];
        if (changing &&
            response_slot(response_slots, batch[p.rays_at + b], p.elements_per_view) != slot) {
          continue;
        }
        g += ray_grads[b];
        ++rays;
      }
      if (rays == 0) continue;
      float d_beta0;
      const float weight = invalid_readings[slot] != 0 ? p.lambda : penalty_weight;
      penalty += beta_penalty(params[p.beta_offset + slot], weight, &d_beta0);
      grad[p.alpha_offset + slot] += g.x;
      if (!p.hold_valid_beta || invalid_readings[slot] != 0) {
        grad[p.beta_offset + slot] += g.y + d_beta0;
      }
    }
  }
  data = group_sum(data, reduce);
  penalty = group_sum(penalty, reduce);
  if (lid == 0) {
    history[2 * p.history_slot] = data;
    history[2 * p.history_slot + 1] = penalty;
  }
}

__kernel void riner_step_backward(const StepParams p, __global const uint* batch,
                                  __constant const GridLevel* levels, __global const float* params,
                                  __global const float* d_sums, __global float* cache,
                                  __global float* grad) {
  const uint i = get_global_id(0);
  if (i >= p.n_samples) return;
  __global const uint* offsets = batch + p.offsets_at;
  const uint b = batch_ray_of(offsets, p.n_batch, i);
  const uint ray = batch[p.rays_at + b];
  const float8 s = batch_segment(batch, &p, b);
  const float d_mu = d_sums[b] * s.s6;
  const uint stride = p.cache_stride;
  float act[MLP_HIDDEN][MLP_WIDTH];
  RINER_UNROLL
  for (int h = 0; h < MLP_HIDDEN; ++h) {
    RINER_UNROLL
    for (int j = 0; j < MLP_WIDTH; ++j) act[h][j] = cache[(CACHE_ACT(h) + j) * stride + i];
  }
  float delta[MLP_HIDDEN][MLP_WIDTH];
  float d_features[N_ENCODED];
  mlp_deltas(params + p.mlp_offset, act, d_mu, delta, d_features);
  RINER_UNROLL
  for (int h = 0; h < MLP_HIDDEN; ++h) {
    RINER_UNROLL
    for (int j = 0; j < MLP_WIDTH; ++j) cache[(CACHE_DELTA(h) + j) * stride + i] = delta[h][j];
  }
  cache[CACHE_DMU * stride + i] = d_mu;
  scale_levels((__global const float*)(batch + p.level_weights_at), d_features);
  float pos[DIMS];
  const uint k = i - offsets[b];
  segment_sample(s, k, p.jitter ? sample_jitter(p.seed, p.step, ray, k) : 0.5f, pos);
#ifdef ATOMIC_GRADIENTS
  if (d_mu != 0.0f) hash_grid_scatter(levels, grad, pos, d_features);
#else
  RINER_UNROLL
  for (int f = 0; f < N_ENCODED; ++f) cache[(CACHE_DIN + f) * stride + i] = d_features[f];
  RINER_UNROLL
  for (int d = 0; d < DIMS; ++d) cache[(CACHE_POS + d) * stride + i] = pos[d];
#endif
}

// Host mirror: ops::FieldGrid (lib/src/ops/riner_step.hpp), 8 four-byte members.
typedef struct {
  uint n;      // voxels this launch evaluates
  uint first;  // the first one's flat index
  uint nx;
  uint ny;
  uint nz;
  float voxel;   // mm
  float extent;  // mm: the encoding's cube
  uint mlp_offset;
} FieldGrid;

__kernel void riner_step_field_evaluate(const FieldGrid g, __constant const GridLevel* levels,
                                        __global const float* level_weights,
                                        __global const float* params, __global float* out) {
  const uint i = get_global_id(0);
  if (i >= g.n) return;
  const uint index = g.first + i;
  const uint k = index % g.nx;
  const uint row = (index / g.nx) % g.ny;
  const uint slice = index / (g.nx * g.ny);
  // Voxel centre (docs/guide/scans.md, "Geometry convention") in the encoding's normalised cube.
  float pos[3];
  pos[0] = ((float)k - 0.5f * (float)(g.nx - 1)) * g.voxel / g.extent + 0.5f;
  pos[1] = (0.5f * (float)(g.ny - 1) - (float)row) * g.voxel / g.extent + 0.5f;
  pos[2] = ((float)slice - 0.5f * (float)(g.nz - 1)) * g.voxel / g.extent + 0.5f;
  float features[N_ENCODED];
  float act[MLP_HIDDEN][MLP_WIDTH];
  hash_grid_encode(levels, params, pos, features);
  scale_levels(level_weights, features);
  out[index] = mlp_forward(params + g.mlp_offset, features, act);
}
