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
