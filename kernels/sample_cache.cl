// sample_cache.cl: what the training step's kernels hand each other per sample, and the packed
// batch they read (helpers only, no __kernel).
//
// The cache holds CACHE_ROWS floats per sample, value v of sample i at cache[v * stride + i]
// (neighbouring work-items touch neighbouring addresses: coalesced on a GPU, contiguous runs
// per work-group on a CPU):
//   CACHE_FEATURES  N_ENCODED rows   encoded features (after the level scales)    forward
//   CACHE_ACT(h)    MLP_WIDTH rows   post-ReLU activations of hidden layer h      forward
//   CACHE_DELTA(h)  MLP_WIDTH rows   dloss/d(pre-activation) of hidden layer h    backward
//   CACHE_DMU       1 row            dloss/dmu of the sample                      backward
//   CACHE_DIN       N_ENCODED rows   dloss/d(feature), after the level scales     backward
//   CACHE_POS       DIMS rows        the sample's normalised position             backward
// The last two are read only by hash_grid_gradient.cl (plans that reduce the grid gradient by
// ownership instead of atomics). The CPU's backward (riner_step_lanes.cl) leaves the last hidden
// layer's CACHE_DELTA rows unwritten: mlp_gradient_blocked forms them from CACHE_ACT and
// CACHE_DMU where it sums them.
//
// The packed batch (uint words; floats by bit pattern), section starts in StepParams:
//   rays [n_batch]             ray ids of the scan
//   offsets [n_batch + 1]      batch ray b owns samples offsets[b] .. offsets[b + 1]
//   weights [n_batch]          data-term weight per ray (float)
//   element_rays               [n_elements + 1] starts, then [n_batch] batch ray indices grouped
//                              by element (ascending within an element)
//   elements [n_elements]      the distinct detector elements, ascending
//   level_weights [N_LEVELS]   coarse-to-fine scale per encoding level (float)
//   segments [8 n_batch]       each batch ray's segment: start xyz, step xyz, dx (float),
//                              sample count (lib/src/model/ray_segments.hpp)
//   rho [n_batch]              each batch ray's reading (float; NaN: invalid)
// The step reads only its own rays' segments and readings, so the scan's tables stay on the
// host and device memory does not grow with the scan.
// Needs hash_grid.cl and mlp.cl (their -D constants).

#define CACHE_FEATURES 0
#define CACHE_ACT(h) (N_ENCODED + (h)*MLP_WIDTH)
#define CACHE_DELTA(h) (N_ENCODED + (MLP_HIDDEN + (h)) * MLP_WIDTH)
#define CACHE_DMU (N_ENCODED + 2 * MLP_HIDDEN * MLP_WIDTH)
#define CACHE_DIN (CACHE_DMU + 1)
#define CACHE_POS (CACHE_DIN + N_ENCODED)
#define CACHE_ROWS (CACHE_POS + DIMS)

// One training step's shape and scalars (host mirror: riner::ops::StepParams, 29 four-byte
// members).
typedef struct {
  uint n_batch;
  uint n_samples;
  uint n_elements;
  uint rays_at;
  uint offsets_at;
  uint weights_at;
  uint element_rays_at;
  uint elements_at;
  uint level_weights_at;
  uint elements_per_view;
  uint alpha_offset;
  uint beta_offset;
  uint mlp_offset;
  uint seed;
  uint step;
  uint jitter;
  uint hold_valid_beta;
  uint history_slot;
  float lambda;
  float relative_beta_threshold;
  float data_weight;
  float ring_lambda;
  uint block_first;
  uint block_views;
  uint block_elements;
  uint cache_stride;
  uint segments_at;
  uint rho_at;
  float starved_floor;  // the bound of a +inf reading (ray_sum.cl)
} StepParams;

// Batch ray b's segment and reading.
RINER_INLINE float8 batch_segment(__global const uint* batch, const StepParams* p, uint b) {
  return as_float8(vload8(b, batch + p->segments_at));
}
RINER_INLINE float batch_rho(__global const uint* batch, const StepParams* p, uint b) {
  return as_float(batch[p->rho_at + b]);
}

// The batch ray that owns sample i: the last b with offsets[b] <= i (rays with no samples own
// none, so they are skipped).
RINER_INLINE uint batch_ray_of(__global const uint* offsets, uint n_batch, uint i) {
  uint lo = 0;
  uint hi = n_batch - 1;
  while (lo < hi) {
    const uint mid = (lo + hi + 1) / 2;
    if (offsets[mid] <= i) {
      lo = mid;
    } else {
      hi = mid - 1;
    }
  }
  return lo;
}

RINER_INLINE void segment_sample(float8 s, uint k, float u, float* pos) {
  const float t = (float)k + u;
  pos[0] = s.s0 + t * s.s3;
  pos[1] = s.s1 + t * s.s4;
#if DIMS == 3
  pos[2] = s.s2 + t * s.s5;
#endif
}

// Coarse to fine: level l's values scaled by weights[l] (and so its gradient).
RINER_INLINE void scale_levels(__global const float* weights, float* values) {
  RINER_UNROLL
  for (int l = 0; l < N_LEVELS; ++l) {
    RINER_UNROLL
    for (int f = 0; f < N_FEATURES; ++f) values[l * N_FEATURES + f] *= weights[l];
  }
}
