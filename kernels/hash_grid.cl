// hash_grid.cl: the multiresolution grid encoding (instant-NGP) and its gradient.
//   Helpers: hash_grid_encode(levels, table, pos, out), hash_grid_scatter(levels, grad, pos, d_out)
//            and, for 16 positions in float16 lanes, hash_grid_encode_lanes and its parts
//   hash_grid_forward(n, levels, table, positions, features)
//     one work-item per point; features [n][N_LEVELS * N_FEATURES]
//   hash_grid_backward(n, levels, positions, d_features, grad)
//     one work-item per point, scattering into grad with GRAD_ADD (compile with
//     -D ATOMIC_GRADIENTS when several work-items share grad)
// -D DIMS (2 or 3), N_LEVELS, N_FEATURES, TABLE_SIZE (entries of a hashed level).
// Level l maps a normalised position x in [0, 1]^DIMS to x * scale + 0.5 grid units and
// interpolates (bi/trilinearly) the features of the surrounding vertices: dense levels index
// vertex (c0, c1, c2) at c0 + res (c1 + res c2), hashed levels at
// (c0 ^ c1 * 2654435761 ^ c2 * 805459861) mod TABLE_SIZE. Feature f of index i of level l is
// table[levels[l].offset + i * N_FEATURES + f]. Host mirror: lib/src/model/parameter_layout.hpp.
// Needs common.cl.

#ifndef DIMS
#error "DIMS must be defined"
#endif
#ifndef N_LEVELS
#error "N_LEVELS must be defined"
#endif
#ifndef N_FEATURES
#error "N_FEATURES must be defined"
#endif
#ifndef TABLE_SIZE
#error "TABLE_SIZE must be defined"
#endif

#define N_CORNERS (1 << DIMS)
#define N_ENCODED (N_LEVELS * N_FEATURES)

typedef struct {
  float scale;
  uint resolution;
  uint offset;
  uint hashed;
} GridLevel;

// The cell a position falls in at one level, and its position inside the cell. The scaled
// position is at least 0.5, so truncation is floor.
RINER_INLINE void hash_grid_cell(__constant const GridLevel* level, const float* pos, uint* cell,
                                 float* frac) {
  RINER_UNROLL
  for (int d = 0; d < DIMS; ++d) {
    const float x = clamp(pos[d], 0.0f, 1.0f) * level->scale + 0.5f;
    cell[d] = (uint)x;
    frac[d] = x - (float)cell[d];
  }
}

// Entries of one level: dense levels hold every vertex, hashed ones TABLE_SIZE.
RINER_INLINE uint hash_grid_entries(__constant const GridLevel* level) {
  if (level->hashed) return TABLE_SIZE;
  uint n = level->resolution;
  RINER_UNROLL
  for (int d = 1; d < DIMS; ++d) n *= level->resolution;
  return n;
}

// Entry (within its level) and interpolation weight of one corner of the cell.
RINER_INLINE uint hash_grid_corner_entry(__constant const GridLevel* level, const uint* cell,
                                         const float* frac, int corner, float* weight) {
  uint coords[DIMS];
  float w = 1.0f;
  RINER_UNROLL
  for (int d = 0; d < DIMS; ++d) {
    const uint upper = (corner >> d) & 1;
    coords[d] = cell[d] + upper;
    w *= upper ? frac[d] : 1.0f - frac[d];
  }
  *weight = w;
  uint index;
  if (level->hashed) {
    index = coords[0] ^ (coords[1] * 2654435761u);
#if DIMS == 3
    index ^= coords[2] * 805459861u;
#endif
    index %= TABLE_SIZE;
  } else {
    index = coords[0] + coords[1] * level->resolution;
#if DIMS == 3
    index += coords[2] * level->resolution * level->resolution;
#endif
  }
  return index;
}

// Parameter index (feature 0) and interpolation weight of one corner of the cell.
RINER_INLINE uint hash_grid_corner(__constant const GridLevel* level, const uint* cell,
                                   const float* frac, int corner, float* weight) {
  return level->offset + hash_grid_corner_entry(level, cell, frac, corner, weight) * N_FEATURES;
}

RINER_INLINE void hash_grid_encode(__constant const GridLevel* levels, __global const float* table,
                                   const float* pos, float* out) {
  RINER_UNROLL
  for (int l = 0; l < N_LEVELS; ++l) {
    __constant const GridLevel* level = &levels[l];
    uint cell[DIMS];
    float frac[DIMS];
    hash_grid_cell(level, pos, cell, frac);
#if N_FEATURES == 2
    if (!level->hashed) {
      // Dense: the two vertices of a cell's edge along x are neighbours in memory, so each
      // pair of corners is one float4 (half the loads of corner by corner).
      uint base = cell[0] + cell[1] * level->resolution;
#if DIMS == 3
      base += cell[2] * level->resolution * level->resolution;
#endif
      float2 acc = (float2)(0.0f);
      RINER_UNROLL
      for (int pair = 0; pair < N_CORNERS / 2; ++pair) {
        uint index = base;
        float w = 1.0f;
        if (pair & 1) index += level->resolution;
        w *= (pair & 1) ? frac[1] : 1.0f - frac[1];
#if DIMS == 3
        if (pair & 2) index += level->resolution * level->resolution;
        w *= (pair & 2) ? frac[2] : 1.0f - frac[2];
#endif
        const float4 v = vload4(0, table + level->offset + index * 2);
        acc += w * ((1.0f - frac[0]) * v.xy + frac[0] * v.zw);
      }
      out[l * 2] = acc.x;
      out[l * 2 + 1] = acc.y;
      continue;
    }
#endif
    float acc[N_FEATURES];
    RINER_UNROLL
    for (int f = 0; f < N_FEATURES; ++f) acc[f] = 0.0f;
    RINER_UNROLL
    for (int c = 0; c < N_CORNERS; ++c) {
      float w;
      const uint index = hash_grid_corner(level, cell, frac, c, &w);
      RINER_UNROLL
      for (int f = 0; f < N_FEATURES; ++f) acc[f] += w * table[index + f];
    }
    RINER_UNROLL
    for (int f = 0; f < N_FEATURES; ++f) out[l * N_FEATURES + f] = acc[f];
  }
}

RINER_INLINE void hash_grid_scatter(__constant const GridLevel* levels, __global float* grad,
                                    const float* pos, const float* d_out) {
  RINER_UNROLL
  for (int l = 0; l < N_LEVELS; ++l) {
    uint cell[DIMS];
    float frac[DIMS];
    hash_grid_cell(&levels[l], pos, cell, frac);
    RINER_UNROLL
    for (int c = 0; c < N_CORNERS; ++c) {
      float w;
      const uint index = hash_grid_corner(&levels[l], cell, frac, c, &w);
      RINER_UNROLL
      for (int f = 0; f < N_FEATURES; ++f)
        GRAD_ADD(&grad[index + f], w * d_out[l * N_FEATURES + f]);
    }
  }
}

// ---- 16 positions at once (the CPU's shape: riner_step_lanes.cl, hash_grid_gradient.cl) ----
// The same arithmetic as the helpers above, lane by lane.

#define GRID_LANES 16

// 16 lanes' values table[at[k]].
RINER_INLINE float16 gather16(__global const float* table, const uint* at) {
  float v[GRID_LANES];
  RINER_UNROLL
  for (int k = 0; k < GRID_LANES; ++k) v[k] = table[at[k]];
  return vload16(0, v);
}

RINER_INLINE void hash_grid_cell_lanes(__constant const GridLevel* level, const float16* pos,
                                       uint16* cell, float16* frac) {
  RINER_UNROLL
  for (int d = 0; d < DIMS; ++d) {
    const float16 x = clamp(pos[d], 0.0f, 1.0f) * level->scale + 0.5f;
    cell[d] = convert_uint16(x);
    frac[d] = x - convert_float16(cell[d]);
  }
}

RINER_INLINE uint16 hash_grid_corner_entry_lanes(__constant const GridLevel* level,
                                                 const uint16* cell, const float16* frac,
                                                 int corner, float16* weight) {
  uint16 coords[DIMS];
  float16 w = 1.0f;
  RINER_UNROLL
  for (int d = 0; d < DIMS; ++d) {
    const uint upper = (corner >> d) & 1;
    coords[d] = cell[d] + upper;
    w *= upper ? frac[d] : 1.0f - frac[d];
  }
  *weight = w;
  uint16 index;
  if (level->hashed) {
    index = coords[0] ^ (coords[1] * 2654435761u);
#if DIMS == 3
    index ^= coords[2] * 805459861u;
#endif
    index %= TABLE_SIZE;
  } else {
    index = coords[0] + coords[1] * level->resolution;
#if DIMS == 3
    index += coords[2] * level->resolution * level->resolution;
#endif
  }
  return index;
}

RINER_INLINE void hash_grid_encode_lanes(__constant const GridLevel* levels,
                                         __global const float* table, const float16* pos,
                                         float16* out) {
  RINER_UNROLL
  for (int l = 0; l < N_LEVELS; ++l) {
    __constant const GridLevel* level = &levels[l];
    uint16 cell[DIMS];
    float16 frac[DIMS];
    hash_grid_cell_lanes(level, pos, cell, frac);
    __global const float* entries = table + level->offset;
#if N_FEATURES == 2
    if (!level->hashed) {
      const uint res = level->resolution;
      uint16 base = cell[0] + cell[1] * res;
#if DIMS == 3
      base += cell[2] * res * res;
#endif
      float16 acc0 = 0.0f;
      float16 acc1 = 0.0f;
      RINER_UNROLL
      for (int pair = 0; pair < N_CORNERS / 2; ++pair) {
        uint16 index = base;
        float16 w = 1.0f;
        if (pair & 1) index += res;
        w *= (pair & 1) ? frac[1] : 1.0f - frac[1];
#if DIMS == 3
        if (pair & 2) index += res * res;
        w *= (pair & 2) ? frac[2] : 1.0f - frac[2];
#endif
        uint at[GRID_LANES];
        vstore16(index * 2, 0, at);
        float v[4][GRID_LANES];
        RINER_UNROLL
        for (int k = 0; k < GRID_LANES; ++k) {
          const float4 e = vload4(0, entries + at[k]);
          v[0][k] = e.x;
          v[1][k] = e.y;
          v[2][k] = e.z;
          v[3][k] = e.w;
        }
        acc0 += w * ((1.0f - frac[0]) * vload16(0, v[0]) + frac[0] * vload16(0, v[2]));
        acc1 += w * ((1.0f - frac[0]) * vload16(0, v[1]) + frac[0] * vload16(0, v[3]));
      }
      out[l * 2] = acc0;
      out[l * 2 + 1] = acc1;
      continue;
    }
#endif
    float16 acc[N_FEATURES];
    RINER_UNROLL
    for (int f = 0; f < N_FEATURES; ++f) acc[f] = 0.0f;
    RINER_UNROLL
    for (int c = 0; c < N_CORNERS; ++c) {
      float16 w;
      uint at[GRID_LANES];
      vstore16(hash_grid_corner_entry_lanes(level, cell, frac, c, &w) * N_FEATURES, 0, at);
      RINER_UNROLL
      for (int f = 0; f < N_FEATURES; ++f) acc[f] += w * gather16(entries + f, at);
    }
    RINER_UNROLL
    for (int f = 0; f < N_FEATURES; ++f) out[l * N_FEATURES + f] = acc[f];
  }
}

__kernel void hash_grid_forward(const uint n, __constant const GridLevel* levels,
                                __global const float* table, __global const float* positions,
                                __global float* features) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  float pos[DIMS];
  for (int d = 0; d < DIMS; ++d) pos[d] = positions[i * DIMS + d];
  float out[N_ENCODED];
  hash_grid_encode(levels, table, pos, out);
  for (int k = 0; k < N_ENCODED; ++k) features[i * N_ENCODED + k] = out[k];
}

__kernel void hash_grid_backward(const uint n, __constant const GridLevel* levels,
                                 __global const float* positions, __global const float* d_features,
                                 __global float* grad) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  float pos[DIMS];
  for (int d = 0; d < DIMS; ++d) pos[d] = positions[i * DIMS + d];
  float d_out[N_ENCODED];
  for (int k = 0; k < N_ENCODED; ++k) d_out[k] = d_features[i * N_ENCODED + k];
  hash_grid_scatter(levels, grad, pos, d_out);
}
