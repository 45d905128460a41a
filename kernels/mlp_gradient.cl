// mlp_gradient.cl: the MLP's weight gradient of a training step as a split-K reduction (the way
// tiny-cuda-nn's fully fused MLP and CUTLASS's split-K GEMM do it): each weight's gradient is a
// sum over the step's samples of its layer's input times its unit's delta, both in the sample
// cache (sample_cache.cl); a bias's is the sum of its unit's delta. Work-group g sums samples
// [g chunk, min((g + 1) chunk, n_samples)) and stores its partial sums
// partials[g MLP_PARAMS + o] once, for every parameter o (mlp.cl's order); adam.cl adds the
// groups' partials in group order. Deterministic, no atomics. Two shapes of the same sums:
//   mlp_gradient_partial(n_samples, chunk, stride, cache, partials)
//     one work-item per parameter (o = lid, lid + size, ...): many narrow work-items (GPUs).
//   mlp_gradient_blocked(n_samples, chunk, stride, cache, params, mlp_offset, partials)
//     one work-item per block of up to 2 x 8 parameters: two inputs of the same 8 units (or
//     the output unit's 8 inputs), 8 samples at a time in float8: few wide work-items that
//     keep their rows in registers (CPUs, where PoCL runs a work-group on one thread). The
//     last hidden layer's deltas are not read from the cache but formed from its activations,
//     d_mu and the output weights (the MLP's from params[mlp_offset]), as mlp_deltas forms them:
//     the CPU's backward (riner_step_lanes.cl) does not store them.
// Needs mlp.cl, sample_cache.cl (and their -D constants).

#define ROW_ONE 0xffffffffu

// The cache rows whose product, summed over samples, is parameter o's gradient (a = ROW_ONE:
// a bias, the sum of row b alone).
RINER_INLINE void mlp_gradient_rows(uint o, uint* a, uint* b) {
  if (o < MLP_B_IN) {
    *a = CACHE_FEATURES + o / MLP_WIDTH;
    *b = CACHE_DELTA(0) + o % MLP_WIDTH;
    return;
  }
  if (o < MLP_B_IN + MLP_WIDTH) {
    *a = ROW_ONE;
    *b = CACHE_DELTA(0) + (o - MLP_B_IN);
    return;
  }
  for (int h = 1; h < MLP_HIDDEN; ++h) {
    if (o < MLP_B_HIDDEN(h)) {
      const uint r = o - MLP_W_HIDDEN(h);
      *a = CACHE_ACT(h - 1) + r / MLP_WIDTH;
      *b = CACHE_DELTA(h) + r % MLP_WIDTH;
      return;
    }
    if (o < MLP_B_HIDDEN(h) + MLP_WIDTH) {
      *a = ROW_ONE;
      *b = CACHE_DELTA(h) + (o - MLP_B_HIDDEN(h));
      return;
    }
  }
  *a = o < MLP_B_OUT ? CACHE_ACT(MLP_HIDDEN - 1) + (o - MLP_W_OUT) : ROW_ONE;
  *b = CACHE_DMU;
}

__kernel void mlp_gradient_partial(const uint n_samples, const uint chunk, const uint stride,
                                   __global const float* cache, __global float* partials) {
  const uint g = get_group_id(0);
  const uint first = min(g * chunk, n_samples);
  const uint last = min(first + chunk, n_samples);
  for (uint o = get_local_id(0); o < MLP_PARAMS; o += get_local_size(0)) {
    uint a;
    uint b;
    mlp_gradient_rows(o, &a, &b);
    __global const float* rb = cache + (size_t)b * stride;
    float4 acc = (float4)(0.0f);
    float tail = 0.0f;
    uint s = first;
    if (a == ROW_ONE) {
      for (; s + 4 <= last; s += 4) acc += vload4(0, rb + s);
      for (; s < last; ++s) tail += rb[s];
    } else {
      __global const float* ra = cache + (size_t)a * stride;
      for (; s + 4 <= last; s += 4) acc = mad(vload4(0, ra + s), vload4(0, rb + s), acc);
      for (; s < last; ++s) tail = mad(ra[s], rb[s], tail);
    }
    partials[g * MLP_PARAMS + o] = (acc.x + acc.y) + (acc.z + acc.w) + tail;
  }
}

// Blocks of 2 x 8 parameters: per layer, (inputs / 2 rounded up + 1) x (units / 8) blocks whose
// two shared rows are two inputs (a layer's odd last input alone; ROW_ONE alone for the
// biases) and whose 8 rows are 8 units' deltas, so each delta row read serves two weights;
// then the output unit's weights as units / 8 blocks sharing the d_mu row; then b_out alone.
#define NO_ROW 0xfffffffeu
#define BLOCKS_IN (((MLP_INPUTS + 1) / 2 + 1) * MLP_V * 2)
#define BLOCKS_HIDDEN (((MLP_WIDTH + 1) / 2 + 1) * MLP_V * 2)
#define BLOCKS_OUT (MLP_V * 2)
#define MLP_BLOCKS (BLOCKS_IN + (MLP_HIDDEN - 1) * BLOCKS_HIDDEN + BLOCKS_OUT + 1)

// Block k of a layer with n_in inputs (rows first_input ..), deltas from first_delta, weights
// from w and biases from b: its shared rows (the second NO_ROW when alone), its first of 8
// consecutive rows, and the parameters of row 0 under each shared row.
RINER_INLINE void layer_block(uint k, uint n_in, uint first_input, uint first_delta, uint w, uint b,
                              uint* shared, uint* rows, uint* param) {
  const uint groups = MLP_WIDTH / 8;
  const uint pair = k / groups;
  const uint unit = k % groups * 8;
  const uint input = 2 * pair;
  *rows = first_delta + unit;
  if (input >= n_in) {  // the biases
    shared[0] = ROW_ONE;
    shared[1] = NO_ROW;
    param[0] = b + unit;
    return;
  }
  shared[0] = first_input + input;
  shared[1] = input + 1 < n_in ? first_input + input + 1 : NO_ROW;
  param[0] = w + input * MLP_WIDTH + unit;
  param[1] = param[0] + MLP_WIDTH;
}

// The last hidden layer's delta of unit `unit` for 8 samples from s, as mlp_deltas forms it:
// d_mu times the unit's output weight where the unit is active.
RINER_INLINE float8 last_deltas8(__global const float* cache, uint stride, uint unit, uint s,
                                 float w_out) {
  const float8 act = vload8(0, cache + (size_t)(CACHE_ACT(MLP_HIDDEN - 1) + unit) * stride + s);
  const float8 d_mu = vload8(0, cache + (size_t)CACHE_DMU * stride + s);
  return select((float8)(0.0f), d_mu * w_out, act > 0.0f);
}

RINER_INLINE float last_delta(__global const float* cache, uint stride, uint unit, uint s,
                              float w_out) {
  const float act = cache[(size_t)(CACHE_ACT(MLP_HIDDEN - 1) + unit) * stride + s];
  return act > 0.0f ? cache[(size_t)CACHE_DMU * stride + s] * w_out : 0.0f;
}

// Row j of a block's 8 delta rows (from r) at 8 samples from s, or at sample s: read, or formed
// (the last hidden layer's, of unit `unit`).
RINER_INLINE float8 delta_rows8(__global const float* cache, uint stride, __global const float* r,
                                int formed, uint unit, int j, uint s, float w_out) {
  return formed ? last_deltas8(cache, stride, unit, s, w_out) : vload8(0, r + j * stride + s);
}

RINER_INLINE float delta_row(__global const float* cache, uint stride, __global const float* r,
                             int formed, uint unit, int j, uint s, float w_out) {
  return formed ? last_delta(cache, stride, unit, s, w_out) : r[j * stride + s];
}

RINER_INLINE void mlp_gradient_block(uint k, uint* shared, uint* rows, uint* param) {
  if (k < BLOCKS_IN) {
    layer_block(k, MLP_INPUTS, CACHE_FEATURES, CACHE_DELTA(0), MLP_W_IN, MLP_B_IN, shared, rows,
                param);
    return;
  }
  k -= BLOCKS_IN;
  for (int h = 1; h < MLP_HIDDEN; ++h) {
    if (k < BLOCKS_HIDDEN) {
      layer_block(k, MLP_WIDTH, CACHE_ACT(h - 1), CACHE_DELTA(h), MLP_W_HIDDEN(h), MLP_B_HIDDEN(h),
                  shared, rows, param);
      return;
    }
    k -= BLOCKS_HIDDEN;
  }
  shared[0] = CACHE_DMU;
  shared[1] = NO_ROW;
  *rows = CACHE_ACT(MLP_HIDDEN - 1) + k * 8;
  param[0] = MLP_W_OUT + k * 8;
}

// (acc.lo + acc.hi) summed pairwise, then the tail: each parameter's sum in one fixed order.
RINER_INLINE float block_total(float8 acc, float tail) {
  const float4 h = acc.lo + acc.hi;
  return (h.x + h.y) + (h.z + h.w) + tail;
}

__kernel void mlp_gradient_blocked(const uint n_samples, const uint chunk, const uint stride,
                                   __global const float* cache, __global const float* params,
                                   const uint mlp_offset, __global float* partials) {
  __global const float* mlp = params + mlp_offset;
  const uint g = get_group_id(0);
  const uint first = min(g * chunk, n_samples);
  const uint end = min(first + chunk, n_samples);
  __global float* out = partials + g * MLP_PARAMS;
  for (uint k = get_local_id(0); k < MLP_BLOCKS; k += get_local_size(0)) {
    if (k == MLP_BLOCKS - 1) {  // b_out: the sum of d_mu
      float sum = 0.0f;
      for (uint s = first; s < end; ++s) sum += cache[CACHE_DMU * stride + s];
      out[MLP_B_OUT] = sum;
      continue;
    }
    uint shared[2];
    uint rows;
    uint param[2];
    mlp_gradient_block(k, shared, &rows, param);
    __global const float* r = cache + (size_t)rows * stride;
    // Deltas of the last hidden layer: formed here (last_deltas8) from unit `unit`.
    const uint last = CACHE_DELTA(MLP_HIDDEN - 1);
    const int formed = rows >= last && rows < last + MLP_WIDTH;
    const uint unit = rows - last;
    float w_out[8];
    RINER_UNROLL
    for (int j = 0; j < 8; ++j) w_out[j] = formed ? mlp[MLP_W_OUT + unit + j] : 0.0f;
    float8 acc[2][8];
    float tail[2][8];
    RINER_UNROLL
    for (int j = 0; j < 8; ++j) {
      acc[0][j] = acc[1][j] = (float8)(0.0f);
      tail[0][j] = tail[1][j] = 0.0f;
    }
    uint s = first;
    if (shared[0] == ROW_ONE) {
      for (; s + 8 <= end; s += 8) {
        RINER_UNROLL
        for (int j = 0; j < 8; ++j)
          acc[0][j] += delta_rows8(cache, stride, r, formed, unit + j, j, s, w_out[j]);
      }
      for (; s < end; ++s) {
        RINER_UNROLL
        for (int j = 0; j < 8; ++j)
          tail[0][j] += delta_row(cache, stride, r, formed, unit + j, j, s, w_out[j]);
      }
    } else {
      // A lone shared row is read as both (its second sums are not stored).
      __global const float* x0 = cache + (size_t)shared[0] * stride;
      __global const float* x1 = shared[1] == NO_ROW ? x0 : cache + (size_t)shared[1] * stride;
      for (; s + 8 <= end; s += 8) {
        const float8 xs0 = vload8(0, x0 + s);
        const float8 xs1 = vload8(0, x1 + s);
        RINER_UNROLL
        for (int j = 0; j < 8; ++j) {
          const float8 rs = delta_rows8(cache, stride, r, formed, unit + j, j, s, w_out[j]);
          acc[0][j] = mad(xs0, rs, acc[0][j]);
          acc[1][j] = mad(xs1, rs, acc[1][j]);
        }
      }
      for (; s < end; ++s) {
        RINER_UNROLL
        for (int j = 0; j < 8; ++j) {
          const float rs = delta_row(cache, stride, r, formed, unit + j, j, s, w_out[j]);
          tail[0][j] = mad(x0[s], rs, tail[0][j]);
          tail[1][j] = mad(x1[s], rs, tail[1][j]);
        }
      }
    }
    RINER_UNROLL
    for (int j = 0; j < 8; ++j) out[param[0] + j] = block_total(acc[0][j], tail[0][j]);
    if (shared[1] != NO_ROW) {
      RINER_UNROLL
      for (int j = 0; j < 8; ++j) out[param[1] + j] = block_total(acc[1][j], tail[1][j]);
    }
  }
}
