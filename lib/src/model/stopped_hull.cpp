#include "model/stopped_hull.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "model/starved_readings.hpp"
#include "riner/rays.hpp"

namespace riner::model {

StoppedHull find_stopped_hull(const Array& image, const Array& readings, const Geometry& g,
                              float floor) {
  StoppedHull out;
  if (!(floor > 0.0f) || std::none_of(readings.data.begin(), readings.data.end(), is_starved)) {
    return out;
  }
  const std::size_t views = g.n_views();
  const std::size_t rows = g.is_3d() ? g.n_v : 1;
  const std::size_t nz = g.is_3d() ? g.volume_shape[0] : 1;
  const std::size_t ny = g.volume_shape[g.is_3d() ? 1 : 0];
  const std::size_t nx = g.volume_shape[g.is_3d() ? 2 : 1];
  std::vector<ViewRotation> rotation(views);
  for (std::size_t v = 0; v < views; ++v) rotation[v] = ViewRotation::of(g, v);
  const float lit = 0.5f * floor;
  std::vector<std::size_t> hull;
  for (std::size_t z = 0; z < nz; ++z) {
    for (std::size_t y = 0; y < ny; ++y) {
      for (std::size_t x = 0; x < nx; ++x) {
        const Vec3 p =
            voxel_centre(g, static_cast<double>(x), static_cast<double>(y), static_cast<double>(z));
        std::size_t bounds = 0, finite = 0;
        bool outside = false;
        for (std::size_t v = 0; v < views && !outside; ++v) {
          const DetectorPoint d = project_to_detector(g, rotation[v], p);
          const long u = std::lround(d.u), w = std::lround(d.v);
          if (u < 0 || u >= static_cast<long>(g.n_u) || w < 0 || w >= static_cast<long>(rows)) {
            continue;
          }
          const float r = readings.data[(v * rows + static_cast<std::size_t>(w)) * g.n_u +
                                        static_cast<std::size_t>(u)];
          if (is_starved(r)) {
            ++bounds;
          } else if (std::isfinite(r)) {
            // A ray that read light (under half the floor) crosses no metal: most voxels stop
            // at their first view.
            outside = r < lit;
            ++finite;
          }
        }
        const double met = static_cast<double>(bounds + finite);
        if (!outside && bounds > 0 && bounds * 2 >= views &&
            static_cast<double>(bounds) >= kHullBoundShare * met) {
          hull.push_back((z * ny + y) * nx + x);
        }
      }
    }
  }
  if (hull.empty()) return out;
  double sum = 0.0;
  for (std::size_t i : hull) sum += image.data[i];
  out.voxels = hull.size();
  out.mean = sum / static_cast<double>(hull.size());
  return out;
}

}  // namespace riner::model
