#include "reference/project_ref.hpp"

#include "reference/joseph_walk.hpp"
#include "riner/array.hpp"
#include "riner/error.hpp"
#include "util/parallel.hpp"

namespace riner::ref {

namespace {

std::size_t rays_of(const Geometry& g) { return g.n_views() * g.n_u * (g.is_3d() ? g.n_v : 1); }

// Detector ray r = (view * n_v + row) * n_u + element.
Ray ray_of(const Geometry& g, std::size_t r) {
  const std::size_t rows = g.is_3d() ? g.n_v : 1;
  const std::size_t element = r % g.n_u;
  const std::size_t row = (r / g.n_u) % rows;
  const std::size_t view = r / (g.n_u * rows);
  return detector_ray(g, view, static_cast<double>(element), static_cast<double>(row));
}

}  // namespace

std::vector<double> project(const Geometry& g, const std::vector<double>& volume) {
  if (volume.size() != shape_size(g.volume_shape)) {
    throw InputError("project: volume size does not match the geometry");
  }
  const GridIndexSpace grid(g);
  std::vector<double> out(rays_of(g));
  util::parallel_for(out.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {
      double sum = 0.0;
      joseph_walk(grid, ray_of(g, r), [&](std::size_t i, double w) { sum += w * volume[i]; });
      out[r] = sum;
    }
  });
  return out;
}

std::vector<double> backproject_adjoint(const Geometry& g, const std::vector<double>& values) {
  if (values.size() != rays_of(g)) {
    throw InputError("backproject: measurement size does not match the geometry");
  }
  const GridIndexSpace grid(g);
  const std::size_t n = shape_size(g.volume_shape);
  // Each thread scatters into its own volume; the fixed-order sum keeps results deterministic.
  std::vector<std::vector<double>> partial =
      util::parallel_map_chunks(values.size(), [&](std::size_t begin, std::size_t end) {
        std::vector<double> volume(n, 0.0);
        for (std::size_t r = begin; r < end; ++r) {
          const double v = values[r];
          if (v == 0.0) continue;
          joseph_walk(grid, ray_of(g, r), [&](std::size_t i, double w) { volume[i] += w * v; });
        }
        return volume;
      });
  std::vector<double> volume(n, 0.0);
  for (const auto& p : partial) {
    for (std::size_t i = 0; i < n; ++i) volume[i] += p[i];
  }
  return volume;
}

std::vector<float> project(const Geometry& g, const std::vector<float>& volume) {
  const std::vector<double> out = project(g, std::vector<double>(volume.begin(), volume.end()));
  return std::vector<float>(out.begin(), out.end());
}

std::vector<float> backproject_adjoint(const Geometry& g, const std::vector<float>& values) {
  const std::vector<double> out =
      backproject_adjoint(g, std::vector<double>(values.begin(), values.end()));
  return std::vector<float>(out.begin(), out.end());
}

}  // namespace riner::ref
