// backproject.cl: the exact adjoint of project.cl (Joseph's method transposed):
// measurement -> volume.
//   backproject_adjoint(n_rays, g, views, values, volume)
//     one work-item per ray, scattering weight * values[r] into the voxels the ray touches
//     with atomic_add_f32: volume must be zeroed first, and sums are not bit-deterministic.
// Needs common.cl, ray_geometry.cl, joseph.cl. No -D constants.
// Buffers as in project.cl.

__kernel void backproject_adjoint(const uint n_rays, const ScanGeometry g,
                                  __global const float2* views, __global const float* values,
                                  __global float* volume) {
  const uint r = get_global_id(0);
  if (r >= n_rays) return;
  const float value = values[r];
  if (value == 0.0f) return;
  float3 origin;
  float3 direction;
  measurement_ray(&g, views, r, &origin, &direction);
  JosephWalk w;
  if (!joseph_setup(&g, origin, direction, &w)) return;
  const int cells = joseph_cells(&g);
  for (int m = w.m_lo; m <= w.m_hi; ++m) {
    for (int c = 0; c < cells; ++c) {
      int index;
      float weight;
      joseph_cell(&w, m, c, &index, &weight);
      if (weight != 0.0f) atomic_add_f32(&volume[index], weight * value);
    }
  }
}
