// fbp.cl: the two device stages of FBP/FDK.
//   fbp_filter(n_out, n_u, taps, in, out)
//     one work-item per output sample; out[line][j] = sum_j' taps[j - j' + n_u - 1] *
//     in[line][j'] (the ramp filter as a linear convolution; taps already hold the spacing).
//   fbp_backproject(n_voxels, first_slice, slice_step, g, views, view_weights, filtered, volume)
//     one work-item per voxel of the selected axial slices first_slice + s * slice_step
//     (volume[s] holds slice s of the selection; 2D: 0 and 1); sums over views the filtered value where the voxel projects
//     (linear in u, bilinear in u and v in 3D), times the view weight and, for divergent beams,
//     the distance weight (SOD / L)^2 with L the voxel's distance from the source along the
//     central ray. Values off the detector count as 0.
// Needs common.cl and ray_geometry.cl. No -D constants.
// Buffers: taps float[2 n_u - 1]; in/out/filtered float[views][rows][n_u]; views float2 (cos,
// sin); view_weights float[views]; volume float[selected slices][ny][nx].

__kernel void fbp_filter(const uint n_out, const int n_u, __global const float* taps,
                         __global const float* in, __global float* out) {
  const uint gid = get_global_id(0);
  if (gid >= n_out) return;
  const int j = gid % n_u;
  __global const float* line = in + (gid - j);
  __global const float* h = taps + j + n_u - 1;  // h[-j'] = taps[j - j' + n_u - 1]
  float sum = 0.0f;
  for (int k = 0; k < n_u; ++k) sum += h[-k] * line[k];
  out[gid] = sum;
}

// Filtered value at continuous detector position (u, v) of one view, zero outside.
inline float sample_detector(__global const float* view, int n_u, int n_v, float u, float v) {
  const float fu = floor(u);
  const float fv = floor(v);
  const int j = (int)fu;
  const int r = (int)fv;
  const float wu = u - fu;
  const float wv = v - fv;
  float value = 0.0f;
  for (int dr = 0; dr < 2; ++dr) {
    const int row = r + dr;
    if (row < 0 || row >= n_v) continue;
    const float w_row = dr ? wv : 1.0f - wv;
    if (j >= 0 && j < n_u) value += w_row * (1.0f - wu) * view[row * n_u + j];
    if (j + 1 >= 0 && j + 1 < n_u) value += w_row * wu * view[row * n_u + j + 1];
  }
  return value;
}

__kernel void fbp_backproject(const uint n_voxels, const uint first_slice, const uint slice_step,
                              const ScanGeometry g,
                              __global const float2* views, __global const float* view_weights,
                              __global const float* filtered, __global float* volume) {
  const uint gid = get_global_id(0);
  if (gid >= n_voxels) return;
  const int k = gid % g.nx;
  const int i = (gid / g.nx) % g.ny;
  const int l = first_slice + gid / (g.nx * g.ny) * slice_step;
  const float x = ((float)k - 0.5f * (float)(g.nx - 1)) * g.voxel;
  const float y = (0.5f * (float)(g.ny - 1) - (float)i) * g.voxel;
  const float z = g.is_3d ? ((float)l - 0.5f * (float)(g.nz - 1)) * g.voxel : 0.0f;
  const int rows = g.is_3d ? g.n_v : 1;
  const int divergent = geometry_is_divergent(&g);
  float sum = 0.0f;
  for (int v = 0; v < g.n_views; ++v) {
    const float2 cs = views[v];
    const float a = x * cs.x + y * cs.y;   // along the detector's u axis
    const float b = -x * cs.y + y * cs.x;  // towards the detector
    float scale = 1.0f;
    float weight = view_weights[v];
    if (divergent) {
      const float distance = g.sod + b;
      scale = (g.sod + g.odd) / distance;
      weight *= (g.sod / distance) * (g.sod / distance);
    }
    const float u = a * scale / g.pitch_u + 0.5f * (float)(g.n_u - 1) - g.offset_u;
    const float row =
        g.is_3d ? z * scale / g.pitch_v + 0.5f * (float)(g.n_v - 1) - g.offset_v : 0.0f;
    sum += weight * sample_detector(filtered + v * rows * g.n_u, g.n_u, rows, u, row);
  }
  volume[gid] = sum;
}
