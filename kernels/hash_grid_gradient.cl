// hash_grid_gradient.cl: the hash grid's gradient of a training step, reduced by ownership
// instead of atomics: the execution plan for CPUs (deterministic, one gradient table, no
// per-thread copies to add up afterwards).
//   hash_grid_gradient_accumulate(n_samples, bands, stride, levels, cache, grad)
//     work-group g owns band g % bands of level N_LEVELS - 1 - g / bands: entries [band E / bands,
//     (band + 1) E / bands) of the level's E entries. Its work-item 0 walks every sample in
//     order (positions and feature gradients from the sample cache, sample_cache.cl) and adds
//     the corners that fall in its band into grad. Each entry has one writer: no atomics, the
//     same sums in the same order every run. Launch levels x bands work-groups of any size
//     (work-items other than 0 idle; the plan uses 1). Each block of 16 samples' cells,
//     weights and products is computed in float16 lanes (hash_grid.cl's lanes helpers); only
//     the carrying and writing go sample by sample. It reads samples below n_samples only, so
//     it serves both shapes of the step's per-sample kernels.
// Consecutive samples of a ray often share corners (at coarse levels, whole cells): their
// sums stay in registers until a corner is left, so memory sees one read-modify-write per run
// instead of a chain of dependent ones through the same address (measured 2x on a CPU). A
// sample in the previous one's cell (most, at the coarse levels) adds its four sums to the held
// ones without the corner-by-corner matching: the grid gradient 8% faster, the same sums.
// Needs common.cl, hash_grid.cl, mlp.cl, sample_cache.cl.

#define NO_ENTRY 0xffffffffu

RINER_INLINE void flush_corner(__global float* table, uint entry, uint lo, uint hi,
                               const float* sum) {
  if (entry < lo || entry >= hi) return;
  RINER_UNROLL
  for (int f = 0; f < N_FEATURES; ++f) table[entry * N_FEATURES + f] += sum[f];
}

// One sample's corners (entry, sum): each held corner is carried into this sample's copy of it
// or written out; then the sample's corners are held.
RINER_INLINE void carry_corners(__global float* table, uint lo, uint hi,
                                const uint entry[N_CORNERS], float sum[N_CORNERS][N_FEATURES],
                                uint held[N_CORNERS], float held_sum[N_CORNERS][N_FEATURES]) {
  RINER_UNROLL
  for (int h = 0; h < N_CORNERS; ++h) {
    if (held[h] == NO_ENTRY) continue;
    int carried = 0;
    RINER_UNROLL
    for (int c = 0; c < N_CORNERS; ++c) {
      if (!carried && entry[c] == held[h]) {
        RINER_UNROLL
        for (int f = 0; f < N_FEATURES; ++f) sum[c][f] += held_sum[h][f];
        carried = 1;
      }
    }
    if (!carried) flush_corner(table, held[h], lo, hi, held_sum[h]);
  }
  RINER_UNROLL
  for (int c = 0; c < N_CORNERS; ++c) {
    held[c] = entry[c];
    RINER_UNROLL
    for (int f = 0; f < N_FEATURES; ++f) held_sum[c][f] = sum[c][f];
  }
}

// Work-group g's level and band [lo, hi) of its entries. Finest level first: its table misses
// the cache most, and threads that take work-groups in order then finish together.
RINER_INLINE uint owned_band(uint g, uint bands, __constant const GridLevel* levels, uint* lo,
                             uint* hi) {
  const uint l = N_LEVELS - 1 - g / bands;
  const uint band = g % bands;
  const uint entries = hash_grid_entries(&levels[l]);
  *lo = (uint)((ulong)band * entries / bands);
  *hi = (uint)((ulong)(band + 1) * entries / bands);
  return l;
}

RINER_INLINE void flush_held(__global float* table, uint lo, uint hi, const uint held[N_CORNERS],
                             float held_sum[N_CORNERS][N_FEATURES]) {
  RINER_UNROLL
  for (int c = 0; c < N_CORNERS; ++c) {
    if (held[c] != NO_ENTRY) flush_corner(table, held[c], lo, hi, held_sum[c]);
  }
}

// Samples first .. first + 15 of a cache row (lanes past n read 0).
RINER_INLINE float16 cache_row_lanes(__global const float* row, uint first, uint n) {
  if (first + GRID_LANES <= n) return vload16(0, row + first);
  float v[GRID_LANES];
  RINER_UNROLL
  for (int k = 0; k < GRID_LANES; ++k) v[k] = first + k < n ? row[first + k] : 0.0f;
  return vload16(0, v);
}

__kernel void hash_grid_gradient_accumulate(const uint n_samples, const uint bands,
                                            const uint stride, __constant const GridLevel* levels,
                                            __global const float* cache, __global float* grad) {
  if (get_local_id(0) != 0 || get_group_id(0) / bands >= N_LEVELS) return;
  uint lo;
  uint hi;
  const uint l = owned_band(get_group_id(0), bands, levels, &lo, &hi);
  __constant const GridLevel* level = &levels[l];
  __global float* table = grad + level->offset;
  uint held[N_CORNERS];  // the previous sample's corners and their running sums
  float held_sum[N_CORNERS][N_FEATURES];
  RINER_UNROLL
  for (int c = 0; c < N_CORNERS; ++c) held[c] = NO_ENTRY;
  for (uint first = 0; first < n_samples; first += GRID_LANES) {
    float16 d_out[N_FEATURES];
    float16 any = 0.0f;
    RINER_UNROLL
    for (int f = 0; f < N_FEATURES; ++f) {
      d_out[f] =
          cache_row_lanes(cache + (CACHE_DIN + l * N_FEATURES + f) * stride, first, n_samples);
      any += fabs(d_out[f]);
    }
    float16 pos[DIMS];
    RINER_UNROLL
    for (int d = 0; d < DIMS; ++d)
      pos[d] = cache_row_lanes(cache + (CACHE_POS + d) * stride, first, n_samples);
    uint16 cell[DIMS];
    float16 frac[DIMS];
    hash_grid_cell_lanes(level, pos, cell, frac);
    uint lane_entry[N_CORNERS][GRID_LANES];
    float lane_sum[N_CORNERS][N_FEATURES][GRID_LANES];
    RINER_UNROLL
    for (int c = 0; c < N_CORNERS; ++c) {
      float16 w;
      vstore16(hash_grid_corner_entry_lanes(level, cell, frac, c, &w), 0, lane_entry[c]);
      RINER_UNROLL
      for (int f = 0; f < N_FEATURES; ++f) vstore16(w * d_out[f], 0, lane_sum[c][f]);
    }
    float lane_any[GRID_LANES];
    vstore16(any, 0, lane_any);
    const uint count = min((uint)GRID_LANES, n_samples - first);
    for (uint k = 0; k < count; ++k) {
      if (lane_any[k] == 0.0f) continue;
      // The previous sample's cell (same corners, same order): carried whole.
      int same = 1;
      RINER_UNROLL
      for (int c = 0; c < N_CORNERS; ++c) same &= lane_entry[c][k] == held[c];
      if (same) {
        RINER_UNROLL
        for (int c = 0; c < N_CORNERS; ++c) {
          RINER_UNROLL
          for (int f = 0; f < N_FEATURES; ++f) held_sum[c][f] += lane_sum[c][f][k];
        }
        continue;
      }
      uint entry[N_CORNERS];
      float sum[N_CORNERS][N_FEATURES];
      RINER_UNROLL
      for (int c = 0; c < N_CORNERS; ++c) {
        entry[c] = lane_entry[c][k];
        RINER_UNROLL
        for (int f = 0; f < N_FEATURES; ++f) sum[c][f] = lane_sum[c][f][k];
      }
      carry_corners(table, lo, hi, entry, sum, held, held_sum);
    }
  }
  flush_held(table, lo, hi, held, held_sum);
}
