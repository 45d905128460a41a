#include "model/ray_segments.hpp"

#include <algorithm>
#include <cmath>

#include "riner/array.hpp"
#include "riner/error.hpp"
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

namespace {

// `rotations`: each view's (ViewRotation::of), so that a ray costs no sine or cosine.
RaySegment segment_of(const Geometry& g, const SamplingDomain& domain,
                      const std::vector<ViewRotation>& rotations, double spacing_mm, bool circle,
                      std::size_t r) {
  const std::size_t rows = g.is_3d() ? g.n_v : 1;
  const std::size_t u = r % g.n_u;
  const std::size_t v = (r / g.n_u) % rows;
  const std::size_t view = r / (g.n_u * rows);
  const Ray ray = detector_ray(g, rotations[view], static_cast<double>(u), static_cast<double>(v));
  const Segment s = circle ? clip_to_cylinder(g, ray) : clip_to_box(g, ray);
  RaySegment out{};
  if (s.empty()) return out;
  const double inv = 1.0 / domain.extent_mm;
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
  return out;
}

void skip_samples(RaySegment& s, std::uint32_t first) {
  for (int a = 0; a < 3; ++a) s.start[a] += static_cast<float>(first) * s.step[a];
}

std::size_t rays_of(const Geometry& g) { return g.n_views() * (g.is_3d() ? g.n_v : 1) * g.n_u; }

std::vector<ViewRotation> rotations_of(const Geometry& g) {
  std::vector<ViewRotation> out(g.n_views());
  for (std::size_t view = 0; view < out.size(); ++view) out[view] = ViewRotation::of(g, view);
  return out;
}

}  // namespace

std::vector<RaySegment> ray_segments(const Geometry& g, double spacing_mm, bool circle) {
  const SamplingDomain domain = sampling_domain(g);
  const std::vector<ViewRotation> rotations = rotations_of(g);
  std::vector<RaySegment> segments(rays_of(g));
  for (std::size_t r = 0; r < segments.size(); ++r) {
    segments[r] = segment_of(g, domain, rotations, spacing_mm, circle, r);
  }
  return segments;
}

RaySegments::RaySegments(const Geometry& g, double spacing_mm, bool circle,
                         std::size_t table_bytes) {
  const std::size_t rays = rays_of(g);
  if (tabled_for(rays, table_bytes)) {
    table_ = ray_segments(g, spacing_mm, circle);
    return;
  }
  geometry_ = g;
  domain_ = sampling_domain(g);
  rotations_ = rotations_of(g);
  spacing_mm_ = spacing_mm;
  circle_ = circle;
  firsts_.assign(rays, 0);
  counts_.resize(rays);
  for (std::size_t r = 0; r < rays; ++r) {
    counts_[r] = segment_of(g, domain_, rotations_, spacing_mm, circle, r).count;
  }
}

RaySegments::RaySegments(std::vector<RaySegment> table) : table_(std::move(table)) {}

RaySegment RaySegments::operator[](std::size_t ray) const {
  if (tabled()) return table_[ray];
  RaySegment s = segment_of(geometry_, domain_, rotations_, spacing_mm_, circle_, ray);
  // Clipped as a table's entry is: one skip by the samples left out, in float.
  if (firsts_[ray]) skip_samples(s, firsts_[ray]);
  s.count = counts_[ray];
  return s;
}

void RaySegments::clip(std::size_t ray, std::uint32_t first, std::uint32_t count) {
  if (tabled()) {
    RaySegment& s = table_[ray];
    skip_samples(s, first);
    s.count = count;
    return;
  }
  if (first && firsts_[ray])
    throw Error("a computed ray segment is clipped once (a table's entry may be clipped again)");
  if (first) firsts_[ray] = first;
  counts_[ray] = count;
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
