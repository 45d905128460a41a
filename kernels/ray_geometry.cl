// ray_geometry.cl: the scan geometry on the device (helpers only, no __kernel). The device copy
// of lib/src/geometry/rays.cpp; conventions in docs/guide/scans.md, "Geometry convention".
//
// ScanGeometry is passed by value; its host mirror is riner::ops::DeviceGeometry (16 four-byte
// members, 64 bytes, no padding). Per-view rotations come as a float2 (cos, sin) table computed
// on the host in double.

#define GEOMETRY_PARALLEL2D 0
#define GEOMETRY_FAN2D 1
#define GEOMETRY_CONE3D 2
#define GEOMETRY_PARALLEL3D 3

typedef struct {
  int type;
  int n_u;
  int n_v;
  int n_views;
  float pitch_u;
  float pitch_v;
  float offset_u;
  float offset_v;
  float sod;
  float odd;
  float voxel;
  int nx;
  int ny;
  int nz;
  int is_3d;
  float grid_z;  // the grid's centre above the source's plane (a cone-beam slab's)
} ScanGeometry;

inline int geometry_is_divergent(const ScanGeometry* g) {
  return g->type == GEOMETRY_FAN2D || g->type == GEOMETRY_CONE3D;
}

// Ray to detector element (u, v) of the view with rotation cs = (cos, sin): origin and unit
// direction in mm. Fan/cone rays start at the source; parallel rays at their closest point to
// the rotation axis.
inline void detector_ray(const ScanGeometry* g, float2 cs, float u, float v, float3* origin,
                         float3* direction) {
  const float a = (u - 0.5f * (float)(g->n_u - 1) + g->offset_u) * g->pitch_u;
  const float z =
      g->is_3d ? (v - 0.5f * (float)(g->n_v - 1) + g->offset_v) * g->pitch_v - g->grid_z : 0.0f;
  if (geometry_is_divergent(g)) {
    const float3 target = (float3)(a * cs.x - g->odd * cs.y, a * cs.y + g->odd * cs.x, z);
    const float3 source = (float3)(g->sod * cs.y, -g->sod * cs.x, -g->grid_z);
    *origin = source;
    *direction = normalize(target - source);
  } else {
    *origin = (float3)(a * cs.x, a * cs.y, z);
    *direction = (float3)(-cs.y, cs.x, 0.0f);
  }
}

// The detector ray of measurement sample r, with r = (view * n_v + row) * n_u + element (row 0
// in 2D): the layout of every measurement buffer.
inline void measurement_ray(const ScanGeometry* g, __global const float2* views, uint r,
                            float3* origin, float3* direction) {
  const int element = r % g->n_u;
  const int row = (r / g->n_u) % g->n_v;
  const int view = r / (g->n_u * g->n_v);
  detector_ray(g, views[view], (float)element, (float)row, origin, direction);
}

// World point -> continuous voxel index (column k, row i, slice l); row 0 is the top (y > 0).
inline float3 world_to_index(const ScanGeometry* g, float3 p) {
  return (float3)(p.x / g->voxel + 0.5f * (float)(g->nx - 1),
                  0.5f * (float)(g->ny - 1) - p.y / g->voxel,
                  g->is_3d ? p.z / g->voxel + 0.5f * (float)(g->nz - 1) : 0.0f);
}
