// joseph.cl: Joseph's method (helpers only, no __kernel). A ray is walked one voxel plane at a
// time along its dominant axis; at each plane the volume is interpolated between the voxel
// centres around the crossing point (linear in 2D, bilinear in 3D), voxels outside the grid
// counting as 0. Device copy of lib/src/reference/joseph_walk.hpp. Needs ray_geometry.cl.
//
// JosephWalk holds the traversal of one ray; joseph_cell(w, m, c, &index, &weight) gives the
// c-th of the (2 or 4) interpolation cells at plane m, with weight 0 for cells off the grid.

typedef struct {
  int main_axis;
  int other0;
  int other1;
  int m_lo;
  int m_hi;
  float base0;
  float slope0;
  float base1;
  float slope1;
  float step_length;  // mm of ray per plane
  int n[3];
  int stride[3];
  // The same by role, as scalars: indexing n and stride by a run-time axis inside the walk
  // keeps them in memory on a CPU device (PoCL) instead of in registers.
  int n0, n1;                  // cells along other0, other1
  int s_main, s_other0, s_other1;  // strides along main_axis, other0, other1
} JosephWalk;

inline float joseph_axis(float3 v, int axis) { return axis == 0 ? v.x : (axis == 1 ? v.y : v.z); }

// Returns 0 when the ray misses the grid.
inline int joseph_setup(const ScanGeometry* g, float3 origin, float3 direction, JosephWalk* w) {
  const float3 o = world_to_index(g, origin);
  const float3 d = (float3)(direction.x, -direction.y, g->is_3d ? direction.z : 0.0f) / g->voxel;
  const int axes = g->is_3d ? 3 : 2;
  w->n[0] = g->nx;
  w->n[1] = g->ny;
  w->n[2] = g->is_3d ? g->nz : 1;
  w->stride[0] = 1;
  w->stride[1] = g->nx;
  w->stride[2] = g->nx * g->ny;
  int main_axis = 0;
  if (fabs(d.y) > fabs(d.x)) main_axis = 1;
  if (axes == 3 && fabs(d.z) > fabs(joseph_axis(d, main_axis))) main_axis = 2;
  const float d_main = joseph_axis(d, main_axis);
  if (d_main == 0.0f) return 0;
  w->main_axis = main_axis;
  w->other0 = main_axis == 0 ? 1 : 0;
  w->other1 = main_axis == 2 ? 1 : 2;
  w->step_length = 1.0f / fabs(d_main);
  float m_lo = 0.0f;
  float m_hi = (float)(w->n[main_axis] - 1);
  for (int k = 0; k < axes - 1; ++k) {
    const int a = k == 0 ? w->other0 : w->other1;
    const float slope = joseph_axis(d, a) / d_main;
    const float base = joseph_axis(o, a) - joseph_axis(o, main_axis) * slope;
    if (k == 0) {
      w->slope0 = slope;
      w->base0 = base;
    } else {
      w->slope1 = slope;
      w->base1 = base;
    }
    // Only planes where -1 < c(m) < n can touch the grid.
    if (slope == 0.0f) {
      if (base <= -1.0f || base >= (float)w->n[a]) return 0;
    } else {
      float lo = (-1.0f - base) / slope;
      float hi = ((float)w->n[a] - base) / slope;
      if (lo > hi) {
        const float t = lo;
        lo = hi;
        hi = t;
      }
      m_lo = fmax(m_lo, ceil(lo));
      m_hi = fmin(m_hi, floor(hi));
    }
  }
  if (axes == 2) {
    w->slope1 = 0.0f;
    w->base1 = 0.0f;
  }
  // Compared as floats: a ray that misses the grid at a near-zero slope (a view at exactly 90
  // degrees: cos is 6e-17) has bounds near 1e17, which no int holds.
  if (!(m_lo <= m_hi)) return 0;
  w->m_lo = (int)m_lo;
  w->m_hi = (int)m_hi;
  w->n0 = w->n[w->other0];
  w->n1 = w->n[w->other1];
  w->s_main = w->stride[main_axis];
  w->s_other0 = w->stride[w->other0];
  w->s_other1 = w->stride[w->other1];
  return 1;
}

// Number of interpolation cells per plane: 2 in 2D, 4 in 3D.
inline int joseph_cells(const ScanGeometry* g) { return g->is_3d ? 4 : 2; }

// Cell `cell` of the plane at `plane` (m times the main axis's stride), whose crossing sits at
// (c0, c1) with floors (f0, f1); weight 0 and index 0 for a cell off the grid.
inline void joseph_plane_cell(const JosephWalk* w, int plane, float c0, float c1, float f0,
                              float f1, int cell, int* index, float* weight) {
  const int i0 = (int)f0 + (cell & 1);
  const int i1 = (int)f1 + (cell >> 1);
  const float w0 = (cell & 1) ? c0 - f0 : 1.0f - (c0 - f0);
  const float w1 = (cell >> 1) ? c1 - f1 : 1.0f - (c1 - f1);
  const int inside = i0 >= 0 && i0 < w->n0 && i1 >= 0 && i1 < w->n1;
  // Selects, not a branch: the work-items of a group stay in step (a CPU device's vectors).
  *index = inside ? plane + i0 * w->s_other0 + i1 * w->s_other1 : 0;
  *weight = inside ? w0 * w1 * w->step_length : 0.0f;
}

inline void joseph_cell(const JosephWalk* w, int m, int cell, int* index, float* weight) {
  // In 2D the second axis is z with one slice, base and slope 0: cells 0 and 1 get weight 1
  // from it and cells 2 and 3 are never asked for.
  const float c0 = w->base0 + (float)m * w->slope0;
  const float c1 = w->base1 + (float)m * w->slope1;
  joseph_plane_cell(w, m * w->s_main, c0, c1, floor(c0), floor(c1), cell, index, weight);
}

// The sum along the walk of weight * volume over every cell, in joseph_cell's order (the same
// floats), each plane's crossing computed once for its cells.
inline float joseph_sum(const JosephWalk* w, int cells, __global const float* volume) {
  float sum = 0.0f;
  for (int m = w->m_lo; m <= w->m_hi; ++m) {
    const float c0 = w->base0 + (float)m * w->slope0;
    const float c1 = w->base1 + (float)m * w->slope1;
    const float f0 = floor(c0);
    const float f1 = floor(c1);
    for (int cell = 0; cell < cells; ++cell) {
      int index;
      float weight;
      joseph_plane_cell(w, m * w->s_main, c0, c1, f0, f1, cell, &index, &weight);
      sum += weight * volume[index];
    }
  }
  return sum;
}
