#include "riner/rays.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace riner {

namespace {

// Offset of element index j from the detector centre, in mm.
double element_offset(double j, std::size_t n, double offset, double pitch) {
  return (j - 0.5 * static_cast<double>(n - 1) + offset) * pitch;
}

Vec3 normalised(Vec3 v) {
  const double n = std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z);
  return {v.x / n, v.y / n, v.z / n};
}

// Slab test on one axis: intersects [enter, exit] with the t where |o + t d| <= half.
void clip_axis(double o, double d, double half, Segment& s) {
  if (d == 0.0) {
    if (std::fabs(o) > half) s.exit = s.enter;  // parallel to the slab and outside it
    return;
  }
  double t0 = (-half - o) / d;
  double t1 = (half - o) / d;
  if (t0 > t1) std::swap(t0, t1);
  s.enter = std::max(s.enter, t0);
  s.exit = std::min(s.exit, t1);
}

}  // namespace

double detector_row_mm(const Geometry& g, double v) {
  return element_offset(v, g.n_v, g.offset_v, g.pitch_v);
}

Vec3 detector_position(const Geometry& g, std::size_t view, double u, double v) {
  return detector_position(g, ViewRotation::of(g, view), u, v);
}

Vec3 detector_position(const Geometry& g, const ViewRotation& rotation, double u, double v) {
  const double c = rotation.c;
  const double s = rotation.s;
  const double a = element_offset(u, g.n_u, g.offset_u, g.pitch_u);
  const double z = g.is_3d() ? detector_row_mm(g, v) - g.grid_centre_z_mm : 0.0;
  // R(theta) (a, b) = (a c - b s, a s + b c); the detector plane is at b = ODD (0 for parallel).
  const double b = g.is_divergent() ? g.origin_detector_mm : 0.0;
  return {a * c - b * s, a * s + b * c, z};
}

std::vector<double> column_ray_distances(const Geometry& g) {
  std::vector<double> d(g.n_u);
  const double middle_row = g.is_3d() ? 0.5 * (static_cast<double>(g.n_v) - 1.0) : 0.0;
  for (std::size_t j = 0; j < g.n_u; ++j) {
    const Ray ray = detector_ray(g, 0, static_cast<double>(j), middle_row);
    const double across = std::hypot(ray.direction.x, ray.direction.y);
    d[j] = (ray.origin.x * ray.direction.y - ray.origin.y * ray.direction.x) / across;
  }
  return d;
}

double grid_beyond_rays(const Geometry& g) {
  const std::vector<double> d = column_ray_distances(g);
  double reach = 0.0;
  for (double x : d) reach = std::max(reach, std::fabs(x));
  // Half an element at the axis beyond the farthest column's centre.
  const double sdd = g.source_origin_mm + g.origin_detector_mm;
  reach += 0.5 * g.pitch_u * (g.is_divergent() ? g.source_origin_mm / sdd : 1.0);
  const std::size_t rank = g.volume_shape.size();
  const double half_width =
      0.5 * g.voxel_mm *
      static_cast<double>(std::max(g.volume_shape[rank - 1], g.volume_shape[rank - 2]));
  return reach > 0.0 ? half_width / reach : 0.0;
}

Ray detector_ray(const Geometry& g, std::size_t view, double u, double v) {
  return detector_ray(g, ViewRotation::of(g, view), u, v);
}

Ray detector_ray(const Geometry& g, const ViewRotation& rotation, double u, double v) {
  const double c = rotation.c;
  const double s = rotation.s;
  const Vec3 target = detector_position(g, rotation, u, v);
  if (g.is_divergent()) {
    const Vec3 source{g.source_origin_mm * s, -g.source_origin_mm * c, -g.grid_centre_z_mm};
    return {source, normalised({target.x - source.x, target.y - source.y, target.z - source.z})};
  }
  return {target, {-s, c, 0.0}};
}

ViewRotation ViewRotation::of(const Geometry& g, std::size_t view) {
  return {std::cos(g.angles[view]), std::sin(g.angles[view])};
}

DetectorPoint project_to_detector(const Geometry& g, std::size_t view, const Vec3& p) {
  return project_to_detector(g, ViewRotation::of(g, view), p);
}

DetectorPoint project_to_detector(const Geometry& g, const ViewRotation& rotation, const Vec3& p) {
  const double c = rotation.c;
  const double s = rotation.s;
  // p in the view's frame: a across the detector, b towards it (R(-theta) p).
  const double a = p.x * c + p.y * s;
  const double b = -p.x * s + p.y * c;
  DetectorPoint d;
  if (g.is_divergent())
    d.magnification = (g.source_origin_mm + g.origin_detector_mm) / (g.source_origin_mm + b);
  d.u = a * d.magnification / g.pitch_u + 0.5 * (static_cast<double>(g.n_u) - 1.0) - g.offset_u;
  if (g.is_3d()) {
    d.v = (p.z + g.grid_centre_z_mm) * d.magnification / g.pitch_v +
          0.5 * (static_cast<double>(g.n_v) - 1.0) - g.offset_v;
  }
  return d;
}

Segment clip_to_box(const Geometry& g, const Ray& ray) {
  const std::size_t rank = g.volume_shape.size();
  const double nx = static_cast<double>(g.volume_shape[rank - 1]);
  const double ny = static_cast<double>(g.volume_shape[rank - 2]);
  Segment s{-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  clip_axis(ray.origin.x, ray.direction.x, 0.5 * nx * g.voxel_mm, s);
  clip_axis(ray.origin.y, ray.direction.y, 0.5 * ny * g.voxel_mm, s);
  if (g.is_3d()) {
    clip_axis(ray.origin.z, ray.direction.z,
              0.5 * static_cast<double>(g.volume_shape[0]) * g.voxel_mm, s);
  }
  if (s.empty()) return {};
  return s;
}

Segment clip_to_cylinder(const Geometry& g, const Ray& ray) {
  const std::size_t rank = g.volume_shape.size();
  const double radius =
      0.5 * g.voxel_mm *
      static_cast<double>(std::min(g.volume_shape[rank - 1], g.volume_shape[rank - 2]));
  // |o_xy + t d_xy|^2 = r^2
  const double a = ray.direction.x * ray.direction.x + ray.direction.y * ray.direction.y;
  const double b = ray.origin.x * ray.direction.x + ray.origin.y * ray.direction.y;
  const double c = ray.origin.x * ray.origin.x + ray.origin.y * ray.origin.y - radius * radius;
  Segment s;
  if (a == 0.0) {
    if (c > 0.0) return {};
    s = {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  } else {
    const double disc = b * b - a * c;
    if (disc <= 0.0) return {};
    const double root = std::sqrt(disc);
    s = {(-b - root) / a, (-b + root) / a};
  }
  if (g.is_3d()) {
    clip_axis(ray.origin.z, ray.direction.z,
              0.5 * static_cast<double>(g.volume_shape[0]) * g.voxel_mm, s);
  }
  if (s.empty()) return {};
  return s;
}

Vec3 voxel_centre(const Geometry& g, double column, double row, double slice) {
  const std::size_t rank = g.volume_shape.size();
  const double nx = static_cast<double>(g.volume_shape[rank - 1]);
  const double ny = static_cast<double>(g.volume_shape[rank - 2]);
  const double nz = g.is_3d() ? static_cast<double>(g.volume_shape[0]) : 1.0;
  return {(column - 0.5 * (nx - 1.0)) * g.voxel_mm, (0.5 * (ny - 1.0) - row) * g.voxel_mm,
          g.is_3d() ? (slice - 0.5 * (nz - 1.0)) * g.voxel_mm : 0.0};
}

}  // namespace riner
