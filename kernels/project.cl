// project.cl: the forward projector (Joseph's method): volume -> measurement.
//   project_forward(n_rays, g, views, volume, out)
//     one work-item per ray; ray r = (view, row, element) with r = (view * n_v + row) * n_u +
//     element (row = 0 in 2D). out[r] = sum over planes of weight * volume (line integral in mm *
//     mu).
// Needs common.cl, ray_geometry.cl, joseph.cl. No -D constants.
// Buffers: views float2[n_views] (cos, sin); volume float[nz][ny][nx]; out float[n_rays].

__kernel void project_forward(const uint n_rays, const ScanGeometry g, __global const float2* views,
                              __global const float* volume, __global float* out) {
  const uint r = get_global_id(0);
  if (r >= n_rays) return;
  float3 origin;
  float3 direction;
  measurement_ray(&g, views, r, &origin, &direction);
  JosephWalk w;
  const float sum = joseph_setup(&g, origin, direction, &w)
                        ? joseph_sum(&w, joseph_cells(&g), volume)
                        : 0.0f;
  out[r] = sum;
}

// ---- The CPU's shape ----
// PoCL vectorises a work-group's work-items only where their loads are contiguous; a ray's
// gathered lookups keep project_forward scalar there. So on a CPU device a work-item walks 16
// neighbouring rays of a detector row at once, in float16 vectors, plane by plane:
//   project_transpose_xy(n, g, volume, volume_t): volume_t[z][x][y] = volume[z][y][x], so that
//     a plane across x holds its lines along y contiguous.
//   project_forward_lanes(n_items, g, views, volume, volume_t, out)
//     item = (view * n_v + row) * groups + group, groups = ceil(n_u / 16); the same sums as
//     project_forward, term by term in the same order.
// At each plane the rays' cells lie along a line of the plane (the other axis in 2D; in 3D two
// to five neighbouring lines): where the group's crossings span at most 28 cells, the work-item
// reads 32 contiguous values of each line and permutes them to its lanes. Elsewhere (a fan
// beam's widest groups, lines under 32 cells, a 3D group spread over more lines) it gathers
// each lane's cells, and a group whose rays do not share their main axis (a fan near 45
// degrees) walks its rays one at a time.

#define PROJECT_LANES 16
#define PROJECT_LINE 32  // values of a line read at a plane: two vectors
// The widest span of a group's crossings (cells) that leaves its cells and their next within
// the 32 values read from just below the lowest (with ROUNDING's slack).
#define PROJECT_MAX_SPAN 28.0f
#define PROJECT_ROUNDING 0.01f
// The widest spread of a 3D group's crossings across its lines (cells): at most 5 lines a plane.
#define PROJECT_MAX_SPREAD 3.0f

__kernel void project_transpose_xy(const uint n, const ScanGeometry g,
                                   __global const float* volume, __global float* volume_t) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  const uint y = i % g.ny;
  const uint x = (i / g.ny) % g.nx;
  const uint z = i / (g.ny * g.nx);
  volume_t[i] = volume[(z * g.ny + y) * g.nx + x];
}

inline float16 gather_lanes(__global const float* volume, const int16 at) {
  return (float16)(volume[at.s0], volume[at.s1], volume[at.s2], volume[at.s3], volume[at.s4],
                   volume[at.s5], volume[at.s6], volume[at.s7], volume[at.s8], volume[at.s9],
                   volume[at.sa], volume[at.sb], volume[at.sc], volume[at.sd], volume[at.se],
                   volume[at.sf]);
}

// (low, high)[at & 31] per lane: one instruction where the compiler offers AVX-512's two-source
// permute (PoCL's shuffle2 is lane by lane: 2.3x slower on a 2048-column projection).
inline float16 permute_line(const float16 low, const float16 high, const uint16 at) {
#ifdef __AVX512F__
  return __builtin_ia32_vpermi2varps512(low, as_int16(at & 31u), high);
#else
  return shuffle2(low, high, at & 31u);
#endif
}

// A line's values at each lane's offsets o and o + 1 from `line`.
inline void line_cells(__global const float* line, const uint16 o, float16* here,
                       float16* next) {
  const float16 low = vload16(0, line);
  const float16 high = vload16(1, line);
  *here = permute_line(low, high, o);
  *next = permute_line(low, high, o + 1u);
}

// The rays of one group, lane by lane: each lane's walk, the planes any of them crosses, and how
// the group reads its cells.
typedef struct {
  float base0[PROJECT_LANES];
  float slope0[PROJECT_LANES];
  float base1[PROJECT_LANES];
  float slope1[PROJECT_LANES];
  float step_length[PROJECT_LANES];
  int m_lo[PROJECT_LANES];  // > m_hi: the lane is past the detector or misses the grid
  int m_hi[PROJECT_LANES];
  int m_first;
  int m_last;
  int mixed;  // the lanes that touch the grid differ in main axis
  JosephWalk shared;  // a touching lane's walk: the axes, sizes and strides all of them share
  // By lines: the lanes lowest along other0 and other1 at every plane, and the lines' strides
  // along the main axis and other1 (in volume_t when the main axis is x).
  int by_lines;
  int lowest0;
  int lowest1;
  int highest1;
  int level1;  // every lane at one whole other1 index
  int line_main;
  int line_other1;
} LaneWalks;

// The touching lanes lowest and highest in base + m * slope at both the first and the last plane
// (then at every plane between: the values are affine in m), and the largest spread between them
// there; returns 0 when no lane is lowest or highest at both.
inline int extreme_lanes(const LaneWalks* lanes, const float* base, const float* slope,
                         int* lowest, int* highest, float* spread) {
  int low[2] = {-1, -1};
  int high[2] = {-1, -1};
  *spread = 0.0f;
  for (int end = 0; end < 2; ++end) {
    const float m = (float)(end == 0 ? lanes->m_first : lanes->m_last);
    for (int k = 0; k < PROJECT_LANES; ++k) {
      if (lanes->m_lo[k] > lanes->m_hi[k]) continue;
      const float c = base[k] + m * slope[k];
      if (low[end] < 0 || c < base[low[end]] + m * slope[low[end]]) low[end] = k;
      if (high[end] < 0 || c > base[high[end]] + m * slope[high[end]]) high[end] = k;
    }
    *spread = fmax(*spread, (base[high[end]] + m * slope[high[end]]) -
                                (base[low[end]] + m * slope[low[end]]));
  }
  *lowest = low[0];
  *highest = high[0];
  return low[0] == low[1] && high[0] == high[1];
}

inline int lane_walks(const ScanGeometry* g, float2 cs, int first_element, int row,
                      LaneWalks* lanes) {
  lanes->m_first = INT_MAX;
  lanes->m_last = INT_MIN;
  lanes->mixed = 0;
  lanes->by_lines = 0;
  int touching = 0;
  for (int k = 0; k < PROJECT_LANES; ++k) {
    lanes->base0[k] = lanes->slope0[k] = lanes->base1[k] = lanes->slope1[k] = 0.0f;
    lanes->step_length[k] = 0.0f;
    lanes->m_lo[k] = 1;
    lanes->m_hi[k] = 0;
    const int element = first_element + k;
    if (element >= g->n_u) continue;
    float3 origin;
    float3 direction;
    detector_ray(g, cs, (float)element, (float)row, &origin, &direction);
    JosephWalk w;
    if (!joseph_setup(g, origin, direction, &w)) continue;
    if (!touching) lanes->shared = w;
    lanes->mixed |= w.main_axis != lanes->shared.main_axis;
    touching = 1;
    lanes->base0[k] = w.base0;
    lanes->slope0[k] = w.slope0;
    lanes->base1[k] = w.base1;
    lanes->slope1[k] = w.slope1;
    lanes->step_length[k] = w.step_length;
    lanes->m_lo[k] = w.m_lo;
    lanes->m_hi[k] = w.m_hi;
    lanes->m_first = min(lanes->m_first, w.m_lo);
    lanes->m_last = max(lanes->m_last, w.m_hi);
  }
  if (!touching || lanes->mixed || lanes->shared.n0 < PROJECT_LINE) return touching;
  float spread0;
  float spread1 = 0.0f;
  int highest0;
  int ordered = extreme_lanes(lanes, lanes->base0, lanes->slope0, &lanes->lowest0, &highest0,
                              &spread0);
  lanes->level1 = 0;
  if (g->is_3d) {
    ordered &= extreme_lanes(lanes, lanes->base1, lanes->slope1, &lanes->lowest1,
                             &lanes->highest1, &spread1);
    // Every ray at the same whole other1 index all along (a parallel beam's row on a slice):
    // the cells at other1 + 1 weigh 0.
    const float level = lanes->base1[lanes->lowest1];
    lanes->level1 = spread1 == 0.0f && level == floor(level);
    for (int k = 0; k < PROJECT_LANES; ++k) {
      lanes->level1 &= lanes->m_lo[k] > lanes->m_hi[k] || lanes->slope1[k] == 0.0f;
    }
  }
  lanes->by_lines = ordered && spread0 <= PROJECT_MAX_SPAN &&
                    spread1 <= PROJECT_MAX_SPREAD - 2.0f * PROJECT_ROUNDING;
  const int main_axis = lanes->shared.main_axis;
  const int plane = g->nx * g->ny;
  lanes->line_main = main_axis == 0 ? g->ny : (main_axis == 1 ? g->nx : plane);
  lanes->line_other1 = main_axis == 2 ? g->nx : plane;
  return touching;
}

// The first cell of the 32 a group reads of a line at a plane: just below its lowest lane's,
// and within the line.
inline int line_start(const float lowest, const int n) {
  return clamp((int)floor(lowest - PROJECT_ROUNDING), 0, n - PROJECT_LINE);
}

// A 2D group's sums: 2 cells per plane, along other0.
inline float16 lanes_sum_2d(const LaneWalks* lanes, __global const float* volume,
                            __global const float* volume_t) {
  const JosephWalk* w = &lanes->shared;
  const float16 base0 = vload16(0, lanes->base0);
  const float16 slope0 = vload16(0, lanes->slope0);
  const float16 step_length = vload16(0, lanes->step_length);
  const int16 m_lo = vload16(0, lanes->m_lo);
  const int16 m_hi = vload16(0, lanes->m_hi);
  __global const float* lines = w->main_axis == 0 ? volume_t : volume;
  float16 sum = 0.0f;
  for (int m = lanes->m_first; m <= lanes->m_last; ++m) {
    const float16 c0 = base0 + (float)m * slope0;
    const float16 f0 = floor(c0);
    const int16 i0 = convert_int16(f0);
    const int16 walking = (int16)(m) >= m_lo & (int16)(m) <= m_hi;
    const int16 in0 = walking & i0 >= 0 & i0 < w->n0;
    const int16 in1 = walking & i0 >= -1 & i0 < w->n0 - 1;
    const float16 t = c0 - f0;
    // In 2D the scalar walk's second factor is 1 (joseph_cell): the same products.
    const float16 weight0 = select((float16)(0.0f), (1.0f - t) * 1.0f * step_length, in0);
    const float16 weight1 = select((float16)(0.0f), t * 1.0f * step_length, in1);
    float16 here;
    float16 next;
    if (lanes->by_lines) {
      const int k = lanes->lowest0;
      const int start = line_start(lanes->base0[k] + (float)m * lanes->slope0[k], w->n0);
      line_cells(lines + m * lanes->line_main + start, as_uint16(i0 - start), &here, &next);
    } else {
      const int16 at = (int16)(m * w->s_main) + i0 * w->s_other0;
      here = gather_lanes(volume, select((int16)(0), at, in0));
      next = gather_lanes(volume, select((int16)(0), at + w->s_other0, in1));
    }
    sum += weight0 * here;
    sum += weight1 * next;
  }
  return sum;
}

// A 3D group's sums: 4 cells per plane, (other0, other1) = (0, 0), (1, 0), (0, 1), (1, 1).
inline float16 lanes_sum_3d(const LaneWalks* lanes, __global const float* volume,
                            __global const float* volume_t) {
  const JosephWalk* w = &lanes->shared;
  const float16 base0 = vload16(0, lanes->base0);
  const float16 slope0 = vload16(0, lanes->slope0);
  const float16 base1 = vload16(0, lanes->base1);
  const float16 slope1 = vload16(0, lanes->slope1);
  const float16 step_length = vload16(0, lanes->step_length);
  const int16 m_lo = vload16(0, lanes->m_lo);
  const int16 m_hi = vload16(0, lanes->m_hi);
  __global const float* lines = w->main_axis == 0 ? volume_t : volume;
  float16 sum = 0.0f;
  for (int m = lanes->m_first; m <= lanes->m_last; ++m) {
    const float16 c0 = base0 + (float)m * slope0;
    const float16 c1 = base1 + (float)m * slope1;
    const float16 f0 = floor(c0);
    const float16 f1 = floor(c1);
    const int16 i0 = convert_int16(f0);
    const int16 i1 = convert_int16(f1);
    const int16 walking = (int16)(m) >= m_lo & (int16)(m) <= m_hi;
    const int16 in0 = i0 >= 0 & i0 < w->n0;
    const int16 in0_next = i0 >= -1 & i0 < w->n0 - 1;
    const int16 in1 = walking & i1 >= 0 & i1 < w->n1;
    const int16 in1_next = walking & i1 >= -1 & i1 < w->n1 - 1;
    const int16 in_a = in0 & in1, in_b = in0_next & in1;
    const int16 in_c = in0 & in1_next, in_d = in0_next & in1_next;
    const float16 t0 = c0 - f0;
    const float16 t1 = c1 - f1;
    const float16 near0 = 1.0f - t0;
    const float16 near1 = 1.0f - t1;
    float16 a, b, c, d;  // the cells (0, 0), (1, 0), (0, 1), (1, 1)
    if (lanes->by_lines) {
      // The lanes' cells lie on lines j .. top + 1, a lane's two on its i1 and i1 + 1.
      const int k0 = lanes->lowest0;
      const int start = line_start(lanes->base0[k0] + (float)m * lanes->slope0[k0], w->n0);
      __global const float* plane = lines + m * lanes->line_main + start;
      const uint16 o = as_uint16(i0 - start);
      const float c_low = lanes->base1[lanes->lowest1] + (float)m * lanes->slope1[lanes->lowest1];
      const int j = lanes->level1 ? (int)c_low : (int)floor(c_low - PROJECT_ROUNDING);
      const int h = lanes->highest1;
      const int top = lanes->level1 ? j
                                    : (int)floor(lanes->base1[h] + (float)m * lanes->slope1[h] +
                                                 PROJECT_ROUNDING);
      const int n1 = w->n1;
      line_cells(plane + clamp(j, 0, n1 - 1) * lanes->line_other1, o, &a, &b);
      if (lanes->level1) {
        c = d = 0.0f;  // their weights are 0
      } else if (top == j) {
        line_cells(plane + clamp(j + 1, 0, n1 - 1) * lanes->line_other1, o, &c, &d);
      } else {
        c = d = 0.0f;
        for (int q = j + 1; q <= top + 1; ++q) {
          float16 here, next;
          line_cells(plane + clamp(q, 0, n1 - 1) * lanes->line_other1, o, &here, &next);
          const int16 on = i1 == (int16)(q);
          const int16 below = i1 == (int16)(q - 1);
          a = select(a, here, on);
          b = select(b, next, on);
          c = select(c, here, below);
          d = select(d, next, below);
        }
      }
    } else {
      const int16 at = (int16)(m * w->s_main) + i0 * w->s_other0 + i1 * w->s_other1;
      const int16 none = 0;
      a = gather_lanes(volume, select(none, at, in_a));
      b = gather_lanes(volume, select(none, at + w->s_other0, in_b));
      c = gather_lanes(volume, select(none, at + w->s_other1, in_c));
      d = gather_lanes(volume, select(none, at + w->s_other0 + w->s_other1, in_d));
    }
    const float16 zero = 0.0f;
    sum += select(zero, near0 * near1 * step_length, in_a) * a;
    sum += select(zero, t0 * near1 * step_length, in_b) * b;
    sum += select(zero, near0 * t1 * step_length, in_c) * c;
    sum += select(zero, t0 * t1 * step_length, in_d) * d;
  }
  return sum;
}

__kernel void project_forward_lanes(const uint n_items, const ScanGeometry g,
                                    __global const float2* views, __global const float* volume,
                                    __global const float* volume_t, __global float* out) {
  const uint item = get_global_id(0);
  if (item >= n_items) return;
  const int groups = (g.n_u + PROJECT_LANES - 1) / PROJECT_LANES;
  const int line = (int)item / groups;  // view * n_v + row
  const int first = ((int)item % groups) * PROJECT_LANES;
  const float2 cs = views[line / g.n_v];
  const int row = line % g.n_v;
  LaneWalks lanes;
  float sums[PROJECT_LANES];
  if (!lane_walks(&g, cs, first, row, &lanes)) {
    vstore16((float16)(0.0f), 0, sums);
  } else if (!lanes.mixed) {
    vstore16(g.is_3d ? lanes_sum_3d(&lanes, volume, volume_t)
                     : lanes_sum_2d(&lanes, volume, volume_t),
             0, sums);
  } else {
    for (int k = 0; k < PROJECT_LANES; ++k) {
      sums[k] = 0.0f;
      if (lanes.m_lo[k] > lanes.m_hi[k]) continue;
      float3 origin;
      float3 direction;
      detector_ray(&g, cs, (float)(first + k), (float)row, &origin, &direction);
      JosephWalk w;
      joseph_setup(&g, origin, direction, &w);
      sums[k] = joseph_sum(&w, joseph_cells(&g), volume);
    }
  }
  __global float* at = out + (size_t)line * g.n_u + first;
  for (int k = 0; k < PROJECT_LANES && first + k < g.n_u; ++k) at[k] = sums[k];
}
