#include "model/ray_segments.hpp"

#include <algorithm>
#include <cmath>

#include "riner/array.hpp"
#include "riner/rays.hpp"

namespace riner::model {

SamplingDomain sampling_domain(const Geometry& g) {
  SamplingDomain d;
  d.dims = g.is_3d() ? 3 : 2;
  std::size_t largest = 0;
  for (std::size_t n : g.volume_shape) largest = std::max(largest, n);
  d.extent_mm = static_cast<double>(largest) * g.voxel_mm;
  return d;
}

std::vector<RaySegment> ray_segments(const Geometry& g, double spacing_mm, bool circle) {
  const SamplingDomain domain = sampling_domain(g);
  const std::size_t rows = g.is_3d() ? g.n_v : 1;
  std::vector<RaySegment> segments(g.n_views() * rows * g.n_u);
  const double inv = 1.0 / domain.extent_mm;
  for (std::size_t r = 0; r < segments.size(); ++r) {
    const std::size_t u = r % g.n_u;
    const std::size_t v = (r / g.n_u) % rows;
    const std::size_t view = r / (g.n_u * rows);
    const Ray ray = detector_ray(g, view, static_cast<double>(u), static_cast<double>(v));
    const Segment s = circle ? clip_to_cylinder(g, ray) : clip_to_box(g, ray);
    RaySegment& out = segments[r];
    out = RaySegment{};
    if (s.empty()) continue;
    const double length = s.length();
    const auto count =
        static_cast<std::uint32_t>(std::max(1.0, std::ceil(length / spacing_mm - 1e-9)));
    const double dx = length / count;
    const double p[3] = {ray.origin.x + s.enter * ray.direction.x,
                         ray.origin.y + s.enter * ray.direction.y,
                         ray.origin.z + s.enter * ray.direction.z};
    const double d[3] = {ray.direction.x, ray.direction.y, ray.direction.z};
    for (int a = 0; a < 3; ++a) {
      const bool used = a < domain.dims;
      out.start[a] = used ? static_cast<float>(p[a] * inv + 0.5) : 0.0f;
      out.step[a] = used ? static_cast<float>(d[a] * dx * inv) : 0.0f;
    }
    out.dx = static_cast<float>(dx);
    out.count = count;
  }
  return segments;
}

std::vector<float> voxel_positions(const Geometry& g) {
  const SamplingDomain domain = sampling_domain(g);
  const std::size_t n = shape_size(g.volume_shape);
  const std::size_t rank = g.volume_shape.size();
  const std::size_t nx = g.volume_shape[rank - 1];
  const std::size_t ny = g.volume_shape[rank - 2];
  std::vector<float> out(n * domain.dims);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec3 c = voxel_centre(g, static_cast<double>(i % nx), static_cast<double>((i / nx) % ny),
                                static_cast<double>(i / (nx * ny)));
    const double p[3] = {c.x, c.y, c.z};
    for (int a = 0; a < domain.dims; ++a) {
      out[i * domain.dims + a] = static_cast<float>(p[a] / domain.extent_mm + 0.5);
    }
  }
  return out;
}

}  // namespace riner::model
