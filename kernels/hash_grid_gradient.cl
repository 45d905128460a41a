// hash_grid_gradient.cl: the hash grid's gradient of a training step, reduced by ownership
// instead of atomics: the execution plan for CPUs (deterministic, one gradient table, no
// per-thread copies to add up afterwards).
//   hash_grid_gradient_accumulate(n_samples, bands, stride, levels, cache, grad)
//     work-group g owns band g % bands of level N_LEVELS - 1 - g / bands: entries [band E / bands,
//     (band + 1) E / bands) of the level's E entries. Its work-item 0 walks every sample in
//     order (positions and feature gradients from the sample cache, sample_cache.cl) and adds
//     the corners that fall in its band into grad. Each entry has one writer: no atomics, the
//     same sums in the same order every run. Launch levels x bands work-groups of any size
//     (work-items other than 0 idle; the plan uses 1).
// Consecutive samples of a ray often share corners (at coarse levels, whole cells): their
// sums stay in registers until a corner is left, so memory sees one read-modify-write per run
// instead of a chain of dependent ones through the same address (measured 2x on a CPU).
// Needs common.cl, hash_grid.cl, mlp.cl, sample_cache.cl.

#define NO_ENTRY 0xffffffffu

RINER_INLINE void flush_corner(__global float* table, uint entry, uint lo, uint hi,
                               const float* sum) {
  if (entry < lo || entry >= hi) return;
  RINER_UNROLL
  for (int f = 0; f < N_FEATURES; ++f) table[entry * N_FEATURES + f] += sum[f];
}

__kernel void hash_grid_gradient_accumulate(const uint n_samples, const uint bands,
                                            const uint stride, __constant const GridLevel* levels,
                                            __global const float* cache, __global float* grad) {
  if (get_local_id(0) != 0) return;
  const uint g = get_group_id(0);
  if (g / bands >= N_LEVELS) return;
  // Finest level first: its table misses the cache most, and threads that take work-groups in
  // order then finish together (longest first).
  const uint l = N_LEVELS - 1 - g / bands;
  const uint band = g % bands;
  __constant const GridLevel* level = &levels[l];
  const uint entries = hash_grid_entries(level);
  const uint lo = (uint)((ulong)band * entries / bands);
  const uint hi = (uint)((ulong)(band + 1) * entries / bands);
  __global float* table = grad + level->offset;
  uint held[N_CORNERS];  // the previous sample's corners and their running sums
  float held_sum[N_CORNERS][N_FEATURES];
  RINER_UNROLL
  for (int c = 0; c < N_CORNERS; ++c) held[c] = NO_ENTRY;
  for (uint i = 0; i < n_samples; ++i) {
    float d_out[N_FEATURES];
    float any = 0.0f;
    RINER_UNROLL
    for (int f = 0; f < N_FEATURES; ++f) {
      d_out[f] = cache[(CACHE_DIN + l * N_FEATURES + f) * stride + i];
      any += fabs(d_out[f]);
    }
    if (any == 0.0f) continue;
    float pos[DIMS];
    RINER_UNROLL
    for (int d = 0; d < DIMS; ++d) pos[d] = cache[(CACHE_POS + d) * stride + i];
    uint cell[DIMS];
    float frac[DIMS];
    hash_grid_cell(level, pos, cell, frac);
    uint entry[N_CORNERS];
    float sum[N_CORNERS][N_FEATURES];
    RINER_UNROLL
    for (int c = 0; c < N_CORNERS; ++c) {
      float w;
      entry[c] = hash_grid_corner_entry(level, cell, frac, c, &w);
      RINER_UNROLL
      for (int f = 0; f < N_FEATURES; ++f) sum[c][f] = w * d_out[f];
    }
    // Carry each held corner into this sample's copy of it, or write it out.
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
  RINER_UNROLL
  for (int c = 0; c < N_CORNERS; ++c) {
    if (held[c] != NO_ENTRY) flush_corner(table, held[c], lo, hi, held_sum[c]);
  }
}
