// fbp.cl: the backprojection stage of FBP/FDK.
//   (the ramp filter along each detector row is kernels/line_filter.cl)
//   fbp_backproject_parallel(n_items, first_slice, slice_step, n_selected, g, views,
//                            view_weights, filtered, volume)
//     the axial slices first_slice + s * slice_step, s < n_selected (volume[s] holds slice s of
//     the selection; 2D: one), each voxel the sum over views of the filtered value where it
//     projects (linear in u, bilinear in u and v in 3D) times the view weight and, for divergent
//     beams, the distance weight (SOD / L)^2 with L the voxel's distance from the source along
//     the central ray; values off the detector count as 0. Parallel beams: one work-item per
//     voxel column (x, y) and block of kParallelSlices selected slices. A parallel beam's voxel
//     projects onto the same u for every slice and onto the same row in every view, so u is
//     found once per view for the block, and each slice's rows and their weights once for all
//     views; off-detector samples are clamped indices with zero weight (no branch in the loop
//     over views).
//     fbp_backproject_parallel_one: the same, one slice per work-item (a 2D scan).
//   fbp_backproject_divergent(...), fbp_backproject_divergent_one(...): the same arguments,
//     for fan and cone beams: a voxel's u, magnification and distance weight in a view do not
//     depend on its height, so they are found once per view for the block of slices, and only
//     each slice's row per view.
//   The GPU's shape: one voxel (column) per work-item; a GPU runs neighbouring work-items
//   together and its caches serve their neighbouring reads.
//
//   fbp_pair_lines(n_items, n_u, first_line, filtered, pairs): detector lines from first_line
//     as pairs, pairs[line][j + 2] = (f(j), f(j + 1)) for j in [-2, n_u], f = 0 off the
//     detector.
//   fbp_backproject_parallel_lanes(n_items, first_slice, slice_step, g, views, view_weights,
//     first_view, chunk_views, accumulate, pairs, volume), fbp_backproject_divergent_lanes(...):
//     the same sums over the views first_view .. + chunk_views (the pairs hold theirs), written
//     into the volume or added to it; the CPU's shape. PoCL
//     vectorises a work-group's work-items only when their loads are contiguous, so a
//     backprojection's lookups left it one voxel at a time: here each work-item holds
//     kLanes voxels of a row in a vector, for kLaneRows rows (their lookups in a view fall on
//     the same detector lines, in cache), and takes both neighbours of a lookup in one read
//     of the pairs; off the detector it reads (0, 0).
// Needs common.cl and ray_geometry.cl. No -D constants.
// Buffers: filtered float[views][rows][n_u]; views float2 (cos,
// sin); view_weights float[views]; volume float[selected slices][ny][nx].

#define kParallelSlices 4

// The height (mm) of slice l's centre in the scan's frame.
inline float slice_height(const ScanGeometry g, const int l) {
  return ((float)l - 0.5f * (float)(g.nz - 1)) * g.voxel + g.grid_z;
}

// A parallel beam's slice l on the detector: its two rows' first values (rows clamped, lines of
// `line` values) and their weights (0 off the detector).
typedef struct {
  int row0, row1;
  float w_row0, w_row1;
} SliceRows;

inline SliceRows parallel_slice_rows(const ScanGeometry g, const int l, const int line) {
  const int rows = g.is_3d ? g.n_v : 1;
  const float z = g.is_3d ? slice_height(g, l) : 0.0f;
  const float v = g.is_3d ? z / g.pitch_v + 0.5f * (float)(g.n_v - 1) - g.offset_v : 0.0f;
  const float fv = floor(v);
  const int r = (int)fv;
  const float wv = v - fv;
  SliceRows out;
  out.w_row0 = (r >= 0 && r < rows) ? 1.0f - wv : 0.0f;
  out.w_row1 = (r + 1 >= 0 && r + 1 < rows) ? wv : 0.0f;
  out.row0 = clamp(r, 0, rows - 1) * line;
  out.row1 = clamp(r + 1, 0, rows - 1) * line;
  return out;
}

// One work-item's block of `slices` (1 or kParallelSlices, a constant where it is inlined, so
// the per-slice arrays stay in registers).
inline void backproject_parallel_block(const uint gid, const uint n_items, const uint first_slice,
                                       const uint slice_step, const uint n_selected,
                                       const ScanGeometry g, __global const float2* views,
                                       __global const float* view_weights,
                                       __global const float* filtered, __global float* volume,
                                       const int slices) {
  if (gid >= n_items) return;
  const uint column = gid % (uint)(g.nx * g.ny);
  const uint block = gid / (uint)(g.nx * g.ny);
  const int k = column % g.nx;
  const int i = column / g.nx;
  const float x = ((float)k - 0.5f * (float)(g.nx - 1)) * g.voxel;
  const float y = (0.5f * (float)(g.ny - 1) - (float)i) * g.voxel;
  const int rows = g.is_3d ? g.n_v : 1;
  // Each slice's two rows (clamped) and their weights (0 off the detector).
  int row0[kParallelSlices], row1[kParallelSlices];
  float w_row0[kParallelSlices], w_row1[kParallelSlices], sum[kParallelSlices];
  for (int s = 0; s < slices; ++s) {
    const uint selected = block * slices + s;
    const SliceRows on =
        parallel_slice_rows(g, first_slice + min(selected, n_selected - 1) * slice_step, g.n_u);
    row0[s] = on.row0;
    row1[s] = on.row1;
    w_row0[s] = on.w_row0;
    w_row1[s] = on.w_row1;
    sum[s] = 0.0f;
  }
  // Slices on the rows' centres (a 2D scan; voxels as tall as the rows) need one row.
  int two_rows = 0;
  for (int s = 0; s < slices; ++s) two_rows |= w_row1[s] != 0.0f;
  const float u_centre = 0.5f * (float)(g.n_u - 1) - g.offset_u;
  for (int view = 0; view < g.n_views; ++view) {
    const float2 cs = views[view];
    const float u = (x * cs.x + y * cs.y) / g.pitch_u + u_centre;
    const float fu = floor(u);
    const int j = (int)fu;
    const float wu = u - fu;
    const float weight = view_weights[view];
    const float w0 = (j >= 0 && j < g.n_u) ? weight * (1.0f - wu) : 0.0f;
    const float w1 = (j + 1 >= 0 && j + 1 < g.n_u) ? weight * wu : 0.0f;
    const int j0 = clamp(j, 0, g.n_u - 1);
    const int j1 = clamp(j + 1, 0, g.n_u - 1);
    __global const float* f = filtered + view * rows * g.n_u;
    for (int s = 0; s < slices; ++s) {
      sum[s] += w_row0[s] * (w0 * f[row0[s] + j0] + w1 * f[row0[s] + j1]);
      if (two_rows) sum[s] += w_row1[s] * (w0 * f[row1[s] + j0] + w1 * f[row1[s] + j1]);
    }
  }
  for (int s = 0; s < slices; ++s) {
    const uint selected = block * slices + s;
    if (selected < n_selected) volume[selected * (uint)(g.nx * g.ny) + column] = sum[s];
  }
}

__kernel void fbp_backproject_parallel(const uint n_items, const uint first_slice,
                                       const uint slice_step, const uint n_selected,
                                       const ScanGeometry g, __global const float2* views,
                                       __global const float* view_weights,
                                       __global const float* filtered, __global float* volume) {
  backproject_parallel_block(get_global_id(0), n_items, first_slice, slice_step, n_selected, g,
                             views, view_weights, filtered, volume, kParallelSlices);
}

// A single slice (a 2D scan, one selected slice): the block of one.
__kernel void fbp_backproject_parallel_one(const uint n_items, const uint first_slice,
                                           const uint slice_step, const uint n_selected,
                                           const ScanGeometry g, __global const float2* views,
                                           __global const float* view_weights,
                                           __global const float* filtered,
                                           __global float* volume) {
  backproject_parallel_block(get_global_id(0), n_items, first_slice, slice_step, n_selected, g,
                             views, view_weights, filtered, volume, 1);
}

inline void backproject_divergent_block(const uint gid, const uint n_items,
                                        const uint first_slice, const uint slice_step,
                                        const uint n_selected, const ScanGeometry g,
                                        __global const float2* views,
                                        __global const float* view_weights,
                                        __global const float* filtered, __global float* volume,
                                        const int slices) {
  if (gid >= n_items) return;
  const uint column = gid % (uint)(g.nx * g.ny);
  const uint block = gid / (uint)(g.nx * g.ny);
  const int k = column % g.nx;
  const int i = column / g.nx;
  const float x = ((float)k - 0.5f * (float)(g.nx - 1)) * g.voxel;
  const float y = (0.5f * (float)(g.ny - 1) - (float)i) * g.voxel;
  const int rows = g.is_3d ? g.n_v : 1;
  float z_over_pitch[kParallelSlices], sum[kParallelSlices];
  for (int s = 0; s < slices; ++s) {
    const uint selected = block * slices + s;
    const int l = first_slice + min(selected, n_selected - 1) * slice_step;
    z_over_pitch[s] =
        g.is_3d ? slice_height(g, l) / g.pitch_v : 0.0f;
    sum[s] = 0.0f;
  }
  const float u_centre = 0.5f * (float)(g.n_u - 1) - g.offset_u;
  const float v_centre = g.is_3d ? 0.5f * (float)(g.n_v - 1) - g.offset_v : 0.0f;
  for (int view = 0; view < g.n_views; ++view) {
    const float2 cs = views[view];
    const float a = x * cs.x + y * cs.y;   // along the detector's u axis
    const float b = -x * cs.y + y * cs.x;  // towards the detector
    const float distance = g.sod + b;
    const float scale = (g.sod + g.odd) / distance;
    const float weight = view_weights[view] * (g.sod / distance) * (g.sod / distance);
    const float u = a * scale / g.pitch_u + u_centre;
    const float fu = floor(u);
    const int j = (int)fu;
    const float wu = u - fu;
    const float w0 = (j >= 0 && j < g.n_u) ? weight * (1.0f - wu) : 0.0f;
    const float w1 = (j + 1 >= 0 && j + 1 < g.n_u) ? weight * wu : 0.0f;
    const int j0 = clamp(j, 0, g.n_u - 1);
    const int j1 = clamp(j + 1, 0, g.n_u - 1);
    __global const float* f = filtered + view * rows * g.n_u;
    for (int s = 0; s < slices; ++s) {
      const float v = z_over_pitch[s] * scale + v_centre;
      const float fv = floor(v);
      const int r = (int)fv;
      const float wv = v - fv;
      const float w_row0 = (r >= 0 && r < rows) ? 1.0f - wv : 0.0f;
      const float w_row1 = (r + 1 >= 0 && r + 1 < rows) ? wv : 0.0f;
      const int row0 = clamp(r, 0, rows - 1) * g.n_u;
      const int row1 = clamp(r + 1, 0, rows - 1) * g.n_u;
      sum[s] += w_row0 * (w0 * f[row0 + j0] + w1 * f[row0 + j1]) +
                w_row1 * (w0 * f[row1 + j0] + w1 * f[row1 + j1]);
    }
  }
  for (int s = 0; s < slices; ++s) {
    const uint selected = block * slices + s;
    if (selected < n_selected) volume[selected * (uint)(g.nx * g.ny) + column] = sum[s];
  }
}

__kernel void fbp_backproject_divergent(const uint n_items, const uint first_slice,
                                        const uint slice_step, const uint n_selected,
                                        const ScanGeometry g, __global const float2* views,
                                        __global const float* view_weights,
                                        __global const float* filtered, __global float* volume) {
  backproject_divergent_block(get_global_id(0), n_items, first_slice, slice_step, n_selected, g,
                              views, view_weights, filtered, volume, kParallelSlices);
}

__kernel void fbp_backproject_divergent_one(const uint n_items, const uint first_slice,
                                            const uint slice_step, const uint n_selected,
                                            const ScanGeometry g, __global const float2* views,
                                            __global const float* view_weights,
                                            __global const float* filtered,
                                            __global float* volume) {
  backproject_divergent_block(get_global_id(0), n_items, first_slice, slice_step, n_selected, g,
                              views, view_weights, filtered, volume, 1);
}

// ---- The CPU's shape ------------------------------------------------------------------------

#define kLanes 16
#define kLaneRows 4

__kernel void fbp_pair_lines(const uint n_items, const int n_u, const uint first_line,
                             __global const float* filtered, __global float2* pairs) {
  const uint gid = get_global_id(0);
  if (gid >= n_items) return;
  const uint per_line = (uint)n_u + 3u;
  __global const float* f = filtered + (first_line + gid / per_line) * (uint)n_u;
  const int j = (int)(gid % per_line) - 2;
  const float here = f[clamp(j, 0, n_u - 1)], next = f[clamp(j + 1, 0, n_u - 1)];
  pairs[gid] = (float2)(j >= 0 && j < n_u ? here : 0.0f, j + 1 >= 0 && j + 1 < n_u ? next : 0.0f);
}

// clamp() of an int16 by scalar bounds, written out: oclgrind 21.10's returns garbage lanes.
inline int16 clamp_lanes(const int16 x, const int lo, const int hi) {
  return min(max(x, (int16)(lo)), (int16)(hi));
}

// The linear interpolation at u of the pairs' line starting at `line` (an index per lane).
inline float16 lanes_interpolate(__global const float2* pairs, const int16 line, const float16 u,
                                 const int n_u) {
  const float16 fu = floor(u);
  const int16 at = line + clamp_lanes(convert_int16(fu), -2, n_u) + 2;
  const float2 q0 = pairs[at.s0], q1 = pairs[at.s1], q2 = pairs[at.s2], q3 = pairs[at.s3],
               q4 = pairs[at.s4], q5 = pairs[at.s5], q6 = pairs[at.s6], q7 = pairs[at.s7],
               q8 = pairs[at.s8], q9 = pairs[at.s9], qa = pairs[at.sa], qb = pairs[at.sb],
               qc = pairs[at.sc], qd = pairs[at.sd], qe = pairs[at.se], qf = pairs[at.sf];
  const float16 a = (float16)(q0.x, q1.x, q2.x, q3.x, q4.x, q5.x, q6.x, q7.x, q8.x, q9.x, qa.x,
                              qb.x, qc.x, qd.x, qe.x, qf.x);
  const float16 b = (float16)(q0.y, q1.y, q2.y, q3.y, q4.y, q5.y, q6.y, q7.y, q8.y, q9.y, qa.y,
                              qb.y, qc.y, qd.y, qe.y, qf.y);
  return a + (u - fu) * (b - a);
}

// A work-item's tile: kLanes columns from k0, kLaneRows rows from i0, of the selected slice
// `selected` (the grid's slice l).
typedef struct {
  int k0, i0;
  uint selected;
  int l;
  float16 x;  // the columns' x (mm)
} LaneTile;

inline LaneTile lane_tile(const uint gid, const ScanGeometry g, const uint first_slice,
                          const uint slice_step) {
  const uint tiles_x = ((uint)g.nx + kLanes - 1) / kLanes;
  const uint tiles = tiles_x * (((uint)g.ny + kLaneRows - 1) / kLaneRows);
  LaneTile t;
  t.selected = gid / tiles;
  t.l = first_slice + t.selected * slice_step;
  t.k0 = (int)((gid % tiles) % tiles_x) * kLanes;
  t.i0 = (int)((gid % tiles) / tiles_x) * kLaneRows;
  const int16 k = (int16)(t.k0) + (int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  t.x = (convert_float16(k) - 0.5f * (float)(g.nx - 1)) * g.voxel;
  return t;
}

inline float lane_row_y(const ScanGeometry g, const int i) {
  return (0.5f * (float)(g.ny - 1) - (float)i) * g.voxel;
}

inline void store_lane_tile(const LaneTile t, const ScanGeometry g, const float16* sum,
                            const int accumulate, __global float* volume) {
  __global float* slice = volume + t.selected * (uint)(g.nx * g.ny);
  for (int r = 0; r < kLaneRows && t.i0 + r < g.ny; ++r) {
    __global float* row = slice + (t.i0 + r) * g.nx + t.k0;
    if (t.k0 + kLanes <= g.nx) {
      vstore16(accumulate ? vload16(0, row) + sum[r] : sum[r], 0, row);
    } else {
      float lanes[kLanes];
      vstore16(sum[r], 0, lanes);
      for (int l = 0; t.k0 + l < g.nx; ++l) row[l] = accumulate ? row[l] + lanes[l] : lanes[l];
    }
  }
}

__kernel void fbp_backproject_parallel_lanes(const uint n_items, const uint first_slice,
                                             const uint slice_step, const ScanGeometry g,
                                             __global const float2* views,
                                             __global const float* view_weights,
                                             const int first_view, const int chunk_views,
                                             const int accumulate,
                                             __global const float2* pairs,
                                             __global float* volume) {
  const uint gid = get_global_id(0);
  if (gid >= n_items) return;
  const LaneTile t = lane_tile(gid, g, first_slice, slice_step);
  const int rows = g.is_3d ? g.n_v : 1;
  const int per_line = g.n_u + 3;
  const SliceRows on = parallel_slice_rows(g, t.l, per_line);
  const float u_centre = 0.5f * (float)(g.n_u - 1) - g.offset_u;
  const float16 x = t.x / g.pitch_u;
  float16 sum[kLaneRows];
  for (int i = 0; i < kLaneRows; ++i) sum[i] = 0.0f;
  for (int c = 0; c < chunk_views; ++c) {
    const float2 cs = views[first_view + c];
    const float weight = view_weights[first_view + c];
    const int16 line0 = (int16)(c * rows * per_line + on.row0);
    const int16 line1 = (int16)(c * rows * per_line + on.row1);
    const float16 ux = x * cs.x + u_centre;
#pragma unroll
    for (int i = 0; i < kLaneRows; ++i) {
      const float16 u = ux + lane_row_y(g, t.i0 + i) / g.pitch_u * cs.y;
      float16 value = on.w_row0 * lanes_interpolate(pairs, line0, u, g.n_u);
      if (on.w_row1 != 0.0f) value += on.w_row1 * lanes_interpolate(pairs, line1, u, g.n_u);
      sum[i] += weight * value;
    }
  }
  store_lane_tile(t, g, sum, accumulate, volume);
}

__kernel void fbp_backproject_divergent_lanes(const uint n_items, const uint first_slice,
                                              const uint slice_step, const ScanGeometry g,
                                              __global const float2* views,
                                              __global const float* view_weights,
                                              const int first_view, const int chunk_views,
                                              const int accumulate,
                                              __global const float2* pairs,
                                              __global float* volume) {
  const uint gid = get_global_id(0);
  if (gid >= n_items) return;
  const LaneTile t = lane_tile(gid, g, first_slice, slice_step);
  const int rows = g.is_3d ? g.n_v : 1;
  const int per_line = g.n_u + 3;
  const float z_over_pitch = g.is_3d ? slice_height(g, t.l) / g.pitch_v : 0.0f;
  const float u_centre = 0.5f * (float)(g.n_u - 1) - g.offset_u;
  const float v_centre = g.is_3d ? 0.5f * (float)(g.n_v - 1) - g.offset_v : 0.0f;
  float16 sum[kLaneRows];
  for (int i = 0; i < kLaneRows; ++i) sum[i] = 0.0f;
  for (int c = 0; c < chunk_views; ++c) {
    const float2 cs = views[first_view + c];
    const float view_weight = view_weights[first_view + c];
    const int first_line = c * rows;
#pragma unroll
    for (int i = 0; i < kLaneRows; ++i) {
      const float y = lane_row_y(g, t.i0 + i);
      const float16 a = t.x * cs.x + y * cs.y;   // along the detector's u axis
      const float16 b = -t.x * cs.y + y * cs.x;  // towards the detector
      const float16 distance = g.sod + b;
      const float16 scale = (g.sod + g.odd) / distance;
      const float16 weight = view_weight * (g.sod / distance) * (g.sod / distance);
      const float16 u = a * scale / g.pitch_u + u_centre;
      if (!g.is_3d) {
        sum[i] += weight * lanes_interpolate(pairs, (int16)(first_line * per_line), u, g.n_u);
        continue;
      }
      const float16 v = z_over_pitch * scale + v_centre;
      const float16 fv = floor(v);
      const int16 r = convert_int16(fv);
      const float16 w_row0 = select((float16)0.0f, 1.0f - (v - fv), r >= 0 && r < rows);
      const float16 w_row1 = select((float16)0.0f, v - fv, r + 1 >= 0 && r + 1 < rows);
      const int16 line0 = (first_line + clamp_lanes(r, 0, rows - 1)) * per_line;
      const int16 line1 = (first_line + clamp_lanes(r + 1, 0, rows - 1)) * per_line;
      sum[i] += weight * (w_row0 * lanes_interpolate(pairs, line0, u, g.n_u) +
                          w_row1 * lanes_interpolate(pairs, line1, u, g.n_u));
    }
  }
  store_lane_tile(t, g, sum, accumulate, volume);
}
