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
// Needs common.cl and ray_geometry.cl. No -D constants.
// Buffers: filtered float[views][rows][n_u]; views float2 (cos,
// sin); view_weights float[views]; volume float[selected slices][ny][nx].

#define kParallelSlices 4

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
    const int l = first_slice + min(selected, n_selected - 1) * slice_step;
    const float z = g.is_3d ? ((float)l - 0.5f * (float)(g.nz - 1)) * g.voxel + g.grid_z : 0.0f;
    const float v = g.is_3d ? z / g.pitch_v + 0.5f * (float)(g.n_v - 1) - g.offset_v : 0.0f;
    const float fv = floor(v);
    const int r = (int)fv;
    const float wv = v - fv;
    w_row0[s] = (r >= 0 && r < rows) ? 1.0f - wv : 0.0f;
    w_row1[s] = (r + 1 >= 0 && r + 1 < rows) ? wv : 0.0f;
    row0[s] = clamp(r, 0, rows - 1) * g.n_u;
    row1[s] = clamp(r + 1, 0, rows - 1) * g.n_u;
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
        g.is_3d ? (((float)l - 0.5f * (float)(g.nz - 1)) * g.voxel + g.grid_z) / g.pitch_v : 0.0f;
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
