#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "riner/error.hpp"
#include "riner/rays.hpp"
#include "riner/ring_correction.hpp"
#include "rings/ring_profile.hpp"
#include "rings/ring_settings.hpp"

namespace riner {

namespace {

// Relative weights of the profile's curvature and size in the fit. The curvature keeps the
// nodes few rays reach (the axis) from taking up what the rest cannot fit: at 1e-4 the axis
// node of the neutron360 scan swung to -0.005/mm and its ring index rose 9x; 0.01-1 give the
// same DeepLesion result (the sought rings are broad anyway).
constexpr double kCurvatureWeight = 0.1;
constexpr double kRidgeWeight = 1e-9;

// Signed distance of each element's ray (view 0) from the rotation axis, in mm.
std::vector<double> ray_distances(const Geometry& g) {
  std::vector<double> d(g.n_u);
  for (std::size_t e = 0; e < g.n_u; ++e) {
    const Ray ray = detector_ray(g, 0, static_cast<double>(e));
    d[e] = ray.origin.x * ray.direction.y - ray.origin.y * ray.direction.x;
  }
  return d;
}

// Per profile node, the fraction of the image's pixels there that are air (pixels shared
// between the two nodes around their radius, as the profile is interpolated).
std::vector<double> air_fraction_per_node(const Array& image, double threshold, std::size_t nodes) {
  const std::size_t ny = image.shape[0];
  const std::size_t nx = image.shape[1];
  const double cx = 0.5 * static_cast<double>(nx - 1);
  const double cy = 0.5 * static_cast<double>(ny - 1);
  std::vector<double> air(nodes, 0.0);
  std::vector<double> all(nodes, 0.0);
  for (std::size_t i = 0; i < ny; ++i) {
    for (std::size_t k = 0; k < nx; ++k) {
      const double r = std::hypot(static_cast<double>(k) - cx, static_cast<double>(i) - cy);
      const auto b = static_cast<std::size_t>(r);
      if (b + 1 >= nodes) continue;
      const double w = r - static_cast<double>(b);
      const double is_air = image(i, k) < threshold ? 1.0 : 0.0;
      air[b] += (1 - w) * is_air;
      air[b + 1] += w * is_air;
      all[b] += 1 - w;
      all[b + 1] += w;
    }
  }
  for (std::size_t b = 0; b < nodes; ++b) air[b] = all[b] > 0.0 ? air[b] / all[b] : 0.0;
  return air;
}

}  // namespace

RingCorrection correct_rings_from_response(const Array& image, const Array& alpha,
                                           const Geometry& geometry,
                                           const std::vector<std::size_t>& dead_elements,
                                           const ResponseRingSettings& settings) {
  rings::check_inputs("response ring correction", image, alpha, geometry);
  rings::validate("response ring correction", settings);
  std::vector<bool> usable(geometry.n_u, true);
  for (std::size_t e : dead_elements) {
    if (e >= geometry.n_u) {
      throw InputError("response ring correction: dead element " + std::to_string(e) +
                       " of a detector with " + std::to_string(geometry.n_u) + " elements");
    }
    usable[e] = false;
  }
  RingCorrection out = rings::unchanged(image, alpha, geometry.voxel_mm);
  if (!rings::all_finite(image)) return out;
  const double threshold = rings::air_threshold(image, settings.air_fraction);
  if (!(threshold > 0.0)) return out;

  // -ln(alpha) of the usable elements and its broad part (a Gaussian over ray distances): what
  // the rings' projections plus one common level have to explain.
  const std::size_t n = geometry.n_u;
  std::vector<double> offset(n, 0.0);
  std::size_t count = 0;
  for (std::size_t e = 0; e < n; ++e) {
    const double a = alpha.data[e];
    usable[e] = usable[e] && std::isfinite(a) && a > 1e-6;
    if (!usable[e]) continue;
    offset[e] = -std::log(a);
    ++count;
  }
  if (count < 2) return out;
  const std::vector<double> distance = ray_distances(geometry);
  const double sigma = settings.scale_px * geometry.voxel_mm;
  // The broad part at ray distance x: NaN where no usable element is near.
  auto broad_at = [&](double x) {
    double sum = 0.0;
    double weight = 0.0;
    for (std::size_t f = 0; f < n; ++f) {
      if (!usable[f]) continue;
      const double t = (distance[f] - x) / sigma;
      if (std::fabs(t) > 4.0) continue;
      const double w = std::exp(-0.5 * t * t);
      sum += w * offset[f];
      weight += w;
    }
    return weight > 0.0 ? sum / weight : std::nan("");
  };
  Eigen::VectorXd broad = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  for (std::size_t e = 0; e < n; ++e) {
    if (usable[e]) broad[static_cast<Eigen::Index>(e)] = broad_at(distance[e]);
  }

  // The evidence: rings make only structure even about the axis, while a detector's own broad
  // structure (chance, a gain gradient, the beam's profile) is as odd as it is even. Compared
  // where an element's mirror distance lies within the usable elements' span.
  double lowest = std::numeric_limits<double>::infinity();
  double highest = -lowest;
  for (std::size_t e = 0; e < n; ++e) {
    if (!usable[e]) continue;
    lowest = std::min(lowest, distance[e]);
    highest = std::max(highest, distance[e]);
  }
  std::vector<double> even;
  double odd_squares = 0.0;
  for (std::size_t e = 0; e < n; ++e) {
    const double mirror = -distance[e];
    if (!usable[e] || mirror < lowest || mirror > highest) continue;
    const double here = broad[static_cast<Eigen::Index>(e)];
    const double there = broad_at(mirror);
    if (!std::isfinite(there)) continue;
    even.push_back(0.5 * (here + there));
    odd_squares += 0.25 * (here - there) * (here - there);
  }
  if (even.size() < 2) return out;
  const double even_mean =
      std::accumulate(even.begin(), even.end(), 0.0) / static_cast<double>(even.size());
  double even_squares = 0.0;
  for (double v : even) even_squares += (v - even_mean) * (v - even_mean);
  out.even_to_odd = odd_squares > 0.0 ? std::sqrt(even_squares / odd_squares)
                                      : std::numeric_limits<double>::infinity();
  if (out.even_to_odd < settings.min_even_to_odd) return out;

  // Least squares over the usable elements: projections of the profile g plus a level (the
  // responses' typical -ln alpha, which no ring can change where rays miss the rings) against
  // the broad part; air holds g at 0, a little curvature and size keep it well posed. g lives
  // inside the grid's inscribed circle (0 from its edge on): beyond it, the grid's corners cut
  // a ring differently in every view, so it would no longer be a per-element offset.
  const std::size_t ny = image.shape[0];
  const std::size_t nx = image.shape[1];
  const std::size_t nodes =
      static_cast<std::size_t>(
          std::ceil(0.5 * std::hypot(static_cast<double>(nx - 1), static_cast<double>(ny - 1)))) +
      2;
  const auto m = static_cast<Eigen::Index>(0.5 * static_cast<double>(std::min(nx, ny) - 1));
  if (m < 3) return out;
  // Every element's projection weights on the solved nodes (all elements: the profile is
  // folded into each one's alpha); the fit's columns are those of the usable elements, then 1
  // for the level.
  Eigen::MatrixXd weights(static_cast<Eigen::Index>(n), m);
  Eigen::VectorXd mask = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(n));
  for (std::size_t e = 0; e < n; ++e) {
    const std::vector<double> w =
        rings::ring_projection_weights(nodes, out.radius_step_mm, geometry, e);
    for (Eigen::Index k = 0; k < m; ++k) {
      weights(static_cast<Eigen::Index>(e), k) = w[static_cast<std::size_t>(k)];
    }
    if (usable[e]) mask[static_cast<Eigen::Index>(e)] = 1.0;
  }
  Eigen::MatrixXd projection(static_cast<Eigen::Index>(n), m + 1);
  projection << mask.asDiagonal() * weights, mask;
  for (Eigen::Index k = 0; k < m; ++k) {
    if (projection.col(k).squaredNorm() > 0.0) ++out.measured_radii;
  }
  if (out.measured_radii == 0) return out;
  Eigen::MatrixXd normal = projection.transpose() * projection;
  const double scale = normal.topLeftCorner(m, m).trace() / static_cast<double>(m);
  const std::vector<double> air = air_fraction_per_node(image, threshold, nodes);
  // Sum over k of (g[k] - 2 g[k+1] + g[k+2])^2, added term by term.
  const double stencil[3] = {1.0, -2.0, 1.0};
  for (Eigen::Index k = 0; k + 2 < m; ++k) {
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        normal(k + a, k + b) += kCurvatureWeight * scale * stencil[a] * stencil[b];
      }
    }
  }
  for (Eigen::Index k = 0; k < m; ++k) {
    normal(k, k) += scale * (settings.air_weight * air[static_cast<std::size_t>(k)] + kRidgeWeight);
  }
  const Eigen::VectorXd gain = normal.ldlt().solve(projection.transpose() * broad);

  // The image gains g, so the profile it loses is -g (0 beyond the solved nodes).
  out.profile.assign(nodes, 0.0);
  for (Eigen::Index k = 0; k < m; ++k) out.profile[static_cast<std::size_t>(k)] = -gain[k];
  const Eigen::VectorXd change = weights * -gain.head(m);
  if (rings::fold_into_alpha(out, std::vector<double>(change.begin(), change.end()),
                             settings.max_mean_response_change)) {
    rings::subtract_profile(out, image, geometry);
  }
  return out;
}

}  // namespace riner
