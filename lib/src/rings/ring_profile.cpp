#include "rings/ring_profile.hpp"

#include <cmath>

#include <string>

#include "riner/error.hpp"
#include "riner/rays.hpp"

namespace riner::rings {

void check_inputs(const char* what, const Array& image, const Array& alpha, const Geometry& g) {
  const std::string name(what);
  if (g.is_3d()) throw InputError(name + ": only 2D geometries");
  if (image.shape != g.volume_shape) {
    throw InputError(name + ": image shape " + shape_string(image.shape) +
                     " is not the geometry's grid " + shape_string(g.volume_shape));
  }
  if (alpha.size() != g.n_u) {
    throw InputError(name + ": alpha has " + std::to_string(alpha.size()) + " values for " +
                     std::to_string(g.n_u) + " detector elements");
  }
}

double ring_projection(const std::vector<double>& profile, double step_mm, const Geometry& g,
                       std::size_t element) {
  const Ray ray = detector_ray(g, 0, static_cast<double>(element));
  const Segment seg = clip_to_box(g, ray);
  if (seg.empty()) return 0.0;
  const double ds = 0.1 * g.voxel_mm;
  const auto n = static_cast<std::size_t>(std::ceil(seg.length() / ds));
  const double h = seg.length() / static_cast<double>(n);
  double sum = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    const double t = seg.enter + (static_cast<double>(j) + 0.5) * h;
    const double x = ray.origin.x + t * ray.direction.x;
    const double y = ray.origin.y + t * ray.direction.y;
    const double r = std::hypot(x, y) / step_mm;
    const auto k = static_cast<std::size_t>(r);
    if (k + 1 >= profile.size()) continue;
    const double w = r - static_cast<double>(k);
    sum += (1.0 - w) * profile[k] + w * profile[k + 1];
  }
  return sum * h;
}

bool fold_into_alpha(RingCorrection& out, const Geometry& g, double max_mean_response_change) {
  std::vector<double> change(g.n_u);
  out.mean_response_change = 0.0;
  for (std::size_t e = 0; e < g.n_u; ++e) {
    change[e] = ring_projection(out.profile, out.radius_step_mm, g, e);
    out.mean_response_change += std::fabs(change[e]) / static_cast<double>(g.n_u);
  }
  out.applied = out.mean_response_change <= max_mean_response_change;
  if (!out.applied) return false;
  for (std::size_t e = 0; e < g.n_u; ++e) {
    out.alpha.data[e] = static_cast<float>(out.alpha.data[e] * std::exp(-change[e]));
  }
  return true;
}

}  // namespace riner::rings
