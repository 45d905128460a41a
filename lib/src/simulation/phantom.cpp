#include "riner/phantom.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "riner/error.hpp"
#include "util/parallel.hpp"

namespace riner {

namespace {

// Modified Shepp-Logan (Toft 1996; the 3D extension after Kak & Slaney, with rotations about z
// only): value, semi-axes a, b, c,
// centre x, y, z (all in units of the phantom radius), rotation about z (degrees).
struct Row {
  double value, a, b, c, x, y, z, phi;
};
constexpr Row kSheppLogan[] = {
    {1.0, 0.6900, 0.920, 0.810, 0.00, 0.0000, 0.00, 0},
    {-0.8, 0.6624, 0.874, 0.780, 0.00, -0.0184, 0.00, 0},
    {-0.2, 0.1100, 0.310, 0.220, 0.22, 0.0000, 0.00, -18},
    {-0.2, 0.1600, 0.410, 0.280, -0.22, 0.0000, 0.00, 18},
    {0.1, 0.2100, 0.250, 0.410, 0.00, 0.3500, -0.15, 0},
    {0.1, 0.0460, 0.046, 0.050, 0.00, 0.1000, 0.25, 0},
    {0.1, 0.0460, 0.046, 0.050, 0.00, -0.1000, 0.25, 0},
    {0.1, 0.0460, 0.023, 0.050, -0.08, -0.6050, 0.00, 0},
    {0.1, 0.0230, 0.023, 0.020, 0.00, -0.6060, 0.00, 0},
    {0.1, 0.0230, 0.046, 0.020, 0.06, -0.6050, 0.00, 0},
};

// A shape's local coordinates, scaled by its sizes: the unit ball of an ellipsoid, [-1, 1]^3 of
// a cuboid. A direction (is_point false) is rotated and scaled, not moved.
template <typename Shape>
Vec3 to_local(const Shape& shape, const Vec3& sizes, const Vec3& p, bool is_point) {
  const Vec3& c = shape.centre;
  const Vec3 q = is_point ? Vec3{p.x - c.x, p.y - c.y, p.z - c.z} : p;
  const auto& r = shape.rotation;
  return {(r[0] * q.x + r[1] * q.y + r[2] * q.z) / sizes.x,
          (r[3] * q.x + r[4] * q.y + r[5] * q.z) / sizes.y,
          (r[6] * q.x + r[7] * q.y + r[8] * q.z) / sizes.z};
}
Vec3 to_local(const Ellipsoid& e, const Vec3& p, bool is_point) {
  return to_local(e, e.semi_axes, p, is_point);
}
Vec3 to_local(const Cuboid& c, const Vec3& p, bool is_point) {
  return to_local(c, c.half_sizes, p, is_point);
}

double dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// World -> local rotation of axes turned by phi about z.
std::array<double, 9> turned_about_z(double phi) {
  return {std::cos(phi), std::sin(phi), 0, -std::sin(phi), std::cos(phi), 0, 0, 0, 1};
}

// The grid's smaller side across the axis (mm): the built-in phantoms scale with it.
double grid_width_mm(const Geometry& g) {
  const std::size_t rank = g.volume_shape.size();
  return g.voxel_mm *
         static_cast<double>(std::min(g.volume_shape[rank - 1], g.volume_shape[rank - 2]));
}

}  // namespace

double Phantom::value_at(const Vec3& p) const {
  double v = 0.0;
  for (const Ellipsoid& e : ellipsoids) {
    const Vec3 q = to_local(e, p, true);
    if (dot(q, q) <= 1.0) v += e.value;
  }
  for (const Cuboid& c : cuboids) {
    const Vec3 q = to_local(c, p, true);
    if (std::fabs(q.x) <= 1.0 && std::fabs(q.y) <= 1.0 && std::fabs(q.z) <= 1.0) v += c.value;
  }
  return v;
}

double Phantom::line_integral(const Ray& ray) const {
  double sum = 0.0;
  for (const Ellipsoid& e : ellipsoids) {
    const Vec3 o = to_local(e, ray.origin, true);
    const Vec3 d = to_local(e, ray.direction, false);
    // |o + t d|^2 = 1 has roots t1 < t2; t is in mm because the world direction is unit.
    const double a = dot(d, d);
    const double b = dot(o, d);
    const double disc = b * b - a * (dot(o, o) - 1.0);
    if (disc > 0.0) sum += e.value * 2.0 * std::sqrt(disc) / a;
  }
  for (const Cuboid& c : cuboids) {
    // Slabs: |o + t d| <= 1 on each local axis; t is in mm as above.
    const Vec3 o = to_local(c, ray.origin, true);
    const Vec3 d = to_local(c, ray.direction, false);
    double enter = -std::numeric_limits<double>::infinity();
    double exit = std::numeric_limits<double>::infinity();
    for (const auto& [oa, da] : {std::pair{o.x, d.x}, std::pair{o.y, d.y}, std::pair{o.z, d.z}}) {
      if (da == 0.0) {
        if (std::fabs(oa) > 1.0) exit = enter;  // parallel to the slab, outside it
        continue;
      }
      const double t0 = (-1.0 - oa) / da, t1 = (1.0 - oa) / da;
      enter = std::max(enter, std::min(t0, t1));
      exit = std::min(exit, std::max(t0, t1));
    }
    if (exit > enter) sum += c.value * (exit - enter);
  }
  return sum;
}

Phantom shepp_logan(const Geometry& g, double mu_scale) {
  g.validate();
  // A negative attenuation brightens the beam: exp(+mu L) overflows the counts.
  if (!(mu_scale > 0.0) || !std::isfinite(mu_scale)) {
    char line[120];
    std::snprintf(line, sizeof(line), "the Shepp-Logan's mu scale must be finite and > 0 (got %g)",
                  mu_scale);
    throw InputError(line);
  }
  const std::size_t rank = g.volume_shape.size();
  const double radius =
      0.95 * 0.5 * g.voxel_mm *
      static_cast<double>(std::min(g.volume_shape[rank - 1], g.volume_shape[rank - 2]));
  const double half_height =
      g.is_3d() ? 0.95 * 0.5 * g.voxel_mm * static_cast<double>(g.volume_shape[0]) : radius;
  Phantom phantom;
  for (const Row& row : kSheppLogan) {
    Ellipsoid e;
    e.value = row.value * mu_scale;
    e.centre = {row.x * radius, row.y * radius, g.is_3d() ? row.z * half_height : 0.0};
    // 2D: an infinitely tall cylinder section; only x, y matter since rays lie in z = 0.
    e.semi_axes = {row.a * radius, row.b * radius, g.is_3d() ? row.c * half_height : 1.0};
    // Local axes rotated by phi: world -> local is the rotation by -phi.
    e.rotation = turned_about_z(row.phi * M_PI / 180.0);
    phantom.ellipsoids.push_back(e);
  }
  return phantom;
}

Phantom faint_square(const Geometry& g) {
  g.validate();
  const double width = grid_width_mm(g);
  const double height = g.is_3d() ? g.voxel_mm * static_cast<double>(g.volume_shape[0]) : 1.0;
  const double side = 0.6 * width;
  const double mu = 0.4 / side;
  const double phi = 20.0 * M_PI / 180.0;
  const std::array<double, 9> turn = turned_about_z(phi);
  // A point given in the square's own axes (fractions of the width), in the world.
  auto at = [&](double a, double b) {
    return Vec3{width * (a * std::cos(phi) - b * std::sin(phi)),
                width * (a * std::sin(phi) + b * std::cos(phi)), 0.0};
  };
  const double z = g.is_3d() ? 0.3 * height : 1.0;
  Phantom p;
  p.cuboids.push_back({{0, 0, 0}, {0.5 * side, 0.5 * side, z}, turn, mu});
  p.cuboids.push_back({at(0.1, 0.0), {0.006 * width, 0.2 * width, 0.8 * z}, turn, 12.0 * mu});
  auto disc = [&](double a, double b, double r, double value) {
    const Vec3 c = at(a, b);
    p.ellipsoids.push_back({c, {r * width, r * width, g.is_3d() ? 0.5 * z : 1.0}, turn, value});
  };
  disc(-0.12, 0.1, 0.05, mu);
  disc(0.0, -0.15, 0.04, -0.5 * mu);
  disc(-0.1, -0.05, 0.02, -mu);
  return p;
}

TubeWallShape tube_wall_shape(const Geometry& g) {
  g.validate();
  const double width = grid_width_mm(g);
  TubeWallShape t;
  t.inner_mm = 0.234 * width;
  t.outer_mm = 0.258 * width;
  return t;
}

Phantom tube_wall(const Geometry& g) {
  const TubeWallShape t = tube_wall_shape(g);
  const double width = grid_width_mm(g);
  const double z = g.is_3d() ? 0.3 * g.voxel_mm * static_cast<double>(g.volume_shape[0]) : 1.0;
  Phantom p;
  // Values add up where discs overlap: water, the wall on it, the tube's content on both.
  auto disc = [&](double x, double y, double r_mm, double value) {
    p.ellipsoids.push_back(
        {{x * width, y * width, 0.0}, {r_mm, r_mm, z}, {1, 0, 0, 0, 1, 0, 0, 0, 1}, value});
  };
  disc(0.0, 0.0, 0.39 * width, t.water);
  disc(0.0, 0.0, t.outer_mm, t.wall - t.water);
  disc(0.0, 0.0, t.inner_mm, t.inside - t.wall);
  disc(0.12, -0.08, 0.04 * width, 0.012);
  disc(-0.14, 0.06, 0.03 * width, -0.008);
  disc(0.29, 0.16, 0.035 * width, 0.015);
  disc(-0.04, -0.31, 0.027 * width, 0.008);
  return p;
}

Array rasterize(const Phantom& phantom, const Geometry& g, int supersample) {
  if (supersample < 1 || supersample > 64) throw InputError("supersample must be in 1..64");
  g.validate();
  Array volume(g.volume_shape);
  const std::size_t rank = g.volume_shape.size();
  const std::size_t nx = g.volume_shape[rank - 1];
  const std::size_t ny = g.volume_shape[rank - 2];
  const std::size_t nz = g.is_3d() ? g.volume_shape[0] : 1;
  const int sz = g.is_3d() ? supersample : 1;
  const double samples = static_cast<double>(supersample) * supersample * sz;
  util::parallel_for(nz * ny, [&](std::size_t begin, std::size_t end) {
    for (std::size_t li = begin; li < end; ++li) {
      const std::size_t l = li / ny;
      const std::size_t i = li % ny;
      for (std::size_t k = 0; k < nx; ++k) {
        double sum = 0.0;
        for (int a = 0; a < sz; ++a) {
          for (int b = 0; b < supersample; ++b) {
            for (int c = 0; c < supersample; ++c) {
              // Sub-sample offsets at the centres of a regular sub-grid of the voxel.
              const double dk = (c + 0.5) / supersample - 0.5;
              const double di = (b + 0.5) / supersample - 0.5;
              const double dl = g.is_3d() ? (a + 0.5) / sz - 0.5 : 0.0;
              sum += phantom.value_at(voxel_centre(g, static_cast<double>(k) + dk,
                                                   static_cast<double>(i) + di,
                                                   static_cast<double>(l) + dl));
            }
          }
        }
        volume.data[(l * ny + i) * nx + k] = static_cast<float>(sum / samples);
      }
    }
  });
  return volume;
}

Array exact_projections(const Phantom& phantom, const Geometry& g) {
  g.validate();
  Array out(g.measurement_shape());
  const std::size_t rows = g.is_3d() ? g.n_v : 1;
  util::parallel_for(out.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {
      const std::size_t element = r % g.n_u;
      const std::size_t row = (r / g.n_u) % rows;
      const std::size_t view = r / (g.n_u * rows);
      const Ray ray = detector_ray(g, view, static_cast<double>(element), static_cast<double>(row));
      out.data[r] = static_cast<float>(phantom.line_integral(ray));
    }
  });
  return out;
}

}  // namespace riner
