#include "rings/ring_profile.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include <string>

#include "riner/error.hpp"
#include "riner/rays.hpp"
#include "rings/radial.hpp"

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

RingCorrection unchanged(const Array& image, const Array& alpha, double radius_step_mm) {
  RingCorrection out;
  out.image = image;
  out.alpha = alpha;
  out.radius_step_mm = radius_step_mm;
  return out;
}

bool all_finite(const Array& image) {
  return std::all_of(image.data.begin(), image.data.end(),
                     [](float v) { return std::isfinite(v); });
}

std::vector<double> ring_projection_weights(std::size_t nodes, double step_mm, const Geometry& g,
                                            std::size_t element) {
  std::vector<double> weights(nodes, 0.0);
  const Ray ray = detector_ray(g, 0, static_cast<double>(element));
  const Segment seg = clip_to_box(g, ray);
  if (seg.empty()) return weights;
  const double ds = kIntegralStepVoxels * g.voxel_mm;
  const auto n = static_cast<std::size_t>(std::ceil(seg.length() / ds));
  const double h = seg.length() / static_cast<double>(n);
  for (std::size_t j = 0; j < n; ++j) {
    const double t = seg.enter + (static_cast<double>(j) + 0.5) * h;
    const double x = ray.origin.x + t * ray.direction.x;
    const double y = ray.origin.y + t * ray.direction.y;
    const double r = std::hypot(x, y) / step_mm;
    const auto k = static_cast<std::size_t>(r);
    if (k + 1 >= nodes) continue;
    const double w = r - static_cast<double>(k);
    weights[k] += (1.0 - w) * h;
    weights[k + 1] += w * h;
  }
  return weights;
}

std::vector<double> ring_projections(const std::vector<double>& profile, double step_mm,
                                     const Geometry& g) {
  std::vector<double> out(g.n_u);
  for (std::size_t e = 0; e < g.n_u; ++e) {
    const std::vector<double> w = ring_projection_weights(profile.size(), step_mm, g, e);
    out[e] = std::inner_product(w.begin(), w.end(), profile.begin(), 0.0);
  }
  return out;
}

double air_threshold(const Array& image, double fraction) {
  if (image.data.empty()) return 0.0;
  std::vector<float> sorted = image.data;
  const auto rank =
      static_cast<std::ptrdiff_t>(kAirReferencePercentile * static_cast<double>(sorted.size() - 1));
  std::nth_element(sorted.begin(), sorted.begin() + rank, sorted.end());
  return fraction * sorted[static_cast<std::size_t>(rank)];
}

void subtract_profile(RingCorrection& out, const Array& image, const Geometry& g) {
  const PixelRadii radii(image.shape[0], image.shape[1], out.radius_step_mm / g.voxel_mm);
  for (std::size_t p = 0; p < image.size(); ++p) {
    const PixelRadii::Between at = radii.between(p);
    const std::size_t b = std::min(at.lower, out.profile.size() - 2);
    const double w = std::min(radii[p] - static_cast<double>(b), 1.0);
    out.image.data[p] =
        image.data[p] - static_cast<float>((1 - w) * out.profile[b] + w * out.profile[b + 1]);
  }
}

void check_dead_elements(const char* what, const std::vector<std::size_t>& dead, std::size_t n_u) {
  for (std::size_t e : dead) {
    if (e >= n_u) {
      throw InputError(std::string(what) + ": dead element " + std::to_string(e) +
                       " of a detector with " + std::to_string(n_u) + " elements");
    }
  }
}

ResponseOffsets response_offsets(const Array& alpha, const std::vector<std::size_t>& dead) {
  constexpr double kSmallestResponse = 1e-6;
  const std::size_t n = alpha.size();
  ResponseOffsets r{std::vector<char>(n, 1), std::vector<double>(n, 0.0)};
  for (std::size_t e : dead) r.usable[e] = 0;
  for (std::size_t e = 0; e < n; ++e) {
    const double a = alpha.data[e];
    r.usable[e] = r.usable[e] && std::isfinite(a) && a > kSmallestResponse;
    if (!r.usable[e]) continue;
    r.offset[e] = -std::log(a);
    ++r.count;
  }
  return r;
}

ProfileNodes profile_nodes(const Array& image, double step_px) {
  const auto ny = static_cast<double>(image.shape[0]);
  const auto nx = static_cast<double>(image.shape[1]);
  ProfileNodes p;
  p.nodes = static_cast<std::size_t>(std::ceil(0.5 * std::hypot(nx - 1.0, ny - 1.0) / step_px)) + 2;
  p.solved = static_cast<Eigen::Index>(0.5 * (std::min(nx, ny) - 1.0) / step_px);
  return p;
}

void move_gain_into_image(RingCorrection& out, const Array& image, const Geometry& g,
                          const Eigen::VectorXd& gain, const Eigen::MatrixXd& weights,
                          std::size_t nodes, double max_mean_response_change) {
  const Eigen::Index solved = weights.cols();
  out.profile.assign(nodes, 0.0);
  for (Eigen::Index k = 0; k < solved; ++k) out.profile[static_cast<std::size_t>(k)] = -gain[k];
  const Eigen::VectorXd change = weights * -gain.head(solved);
  if (fold_into_alpha(out, std::vector<double>(change.begin(), change.end()),
                      max_mean_response_change)) {
    subtract_profile(out, image, g);
  }
}

bool fold_into_alpha(RingCorrection& out, const std::vector<double>& change,
                     double max_mean_response_change) {
  const std::size_t n = change.size();
  out.mean_response_change = 0.0;
  for (double c : change) out.mean_response_change += std::fabs(c) / static_cast<double>(n);
  out.applied = out.mean_response_change <= max_mean_response_change;
  if (!out.applied) return false;
  for (std::size_t e = 0; e < n; ++e) {
    out.alpha.data[e] = static_cast<float>(out.alpha.data[e] * std::exp(-change[e]));
  }
  return true;
}

}  // namespace riner::rings
