#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "riner/rays.hpp"
#include "riner/ring_correction.hpp"
#include "rings/radial.hpp"
#include "rings/ring_profile.hpp"
#include "rings/ring_settings.hpp"

namespace riner {

namespace {

// Relative weights of the profile's curvature and size in the fit. The curvature keeps the
// nodes few rays reach (the axis) from taking up what the rest cannot fit
// (docs/history/RESULTS.md).
constexpr double kCurvatureWeight = 0.1;
constexpr double kRidgeWeight = 1e-9;

// Per profile node, the fraction of the image's pixels there that are air (pixels shared
// between the two nodes around their radius, as the profile is interpolated).
std::vector<double> air_fraction_per_node(const Array& image, double threshold, std::size_t nodes) {
  std::vector<float> is_air(image.size());
  for (std::size_t p = 0; p < image.size(); ++p)
    is_air[p] = image.data[p] < threshold ? 1.0f : 0.0f;
  return rings::PixelRadii(image.shape[0], image.shape[1], 1.0).angular_means(is_air, nodes);
}

// -ln(alpha) across the detector and its broad part: what rings and one common level have to
// explain.
struct ResponseStructure {
  std::vector<char> usable;      // live elements with a positive, finite alpha
  std::vector<double> distance;  // ray distances from the axis (mm)
  std::vector<double> offset;    // -ln(alpha), 0 where not usable
  std::vector<double> broad;     // its Gaussian over ray distances, 0 where not usable
  double sigma_mm = 0.0;
  std::size_t count = 0;  // usable elements

  double broad_at(double x) const {
    return rings::gaussian_mean_at(distance, offset, usable, x, sigma_mm);
  }
};

ResponseStructure response_structure(const Array& alpha, const Geometry& g,
                                     const std::vector<std::size_t>& dead, double scale_px) {
  ResponseStructure r;
  const std::size_t n = g.n_u;
  rings::ResponseOffsets offsets = rings::response_offsets(alpha, dead);
  r.usable = std::move(offsets.usable);
  r.offset = std::move(offsets.offset);
  r.count = offsets.count;
  r.distance = column_ray_distances(g);
  r.sigma_mm = scale_px * g.voxel_mm;
  r.broad.assign(n, 0.0);
  for (std::size_t e = 0; e < n; ++e) {
    if (r.usable[e]) r.broad[e] = r.broad_at(r.distance[e]);
  }
  return r;
}

// The evidence: rings make only structure even about the axis, while a detector's own broad
// structure (chance, a gain gradient, the beam's profile) is as odd as it is even. The rms of
// the even part over the odd one, where an element's mirror distance lies within the usable
// elements' span; 0 when too few elements have a mirror.
double even_to_odd(const ResponseStructure& r) {
  double lowest = std::numeric_limits<double>::infinity();
  double highest = -lowest;
  for (std::size_t e = 0; e < r.usable.size(); ++e) {
    if (!r.usable[e]) continue;
    lowest = std::min(lowest, r.distance[e]);
    highest = std::max(highest, r.distance[e]);
  }
  std::vector<double> even;
  double odd_squares = 0.0;
  for (std::size_t e = 0; e < r.usable.size(); ++e) {
    const double mirror = -r.distance[e];
    if (!r.usable[e] || mirror < lowest || mirror > highest) continue;
    const double there = r.broad_at(mirror);
    if (!std::isfinite(there)) continue;
    even.push_back(0.5 * (r.broad[e] + there));
    odd_squares += 0.25 * (r.broad[e] - there) * (r.broad[e] - there);
  }
  if (even.size() < 2) return 0.0;
  const double even_mean =
      std::accumulate(even.begin(), even.end(), 0.0) / static_cast<double>(even.size());
  double even_squares = 0.0;
  for (double v : even) even_squares += (v - even_mean) * (v - even_mean);
  return odd_squares > 0.0 ? std::sqrt(even_squares / odd_squares)
                           : std::numeric_limits<double>::infinity();
}

// The fit: least squares over the usable elements of the profile's projections plus a level
// (the responses' typical -ln alpha, which no ring can change where rays miss the rings)
// against the broad part; air holds the profile at 0, a little curvature and size keep it well
// posed. The profile lives inside the grid's inscribed circle (`solved` nodes; 0 from its edge
// on): beyond it, the grid's corners cut a ring differently in every view, so it would no
// longer be a per-element offset. Returns the image's gain per solved node; `weights` gets
// every element's projection weights on them (all elements: the change is folded into each
// one's alpha).
Eigen::VectorXd fit_gain(const ResponseStructure& r, const Array& image, const Geometry& g,
                         const ResponseRingSettings& settings, double threshold, double step_mm,
                         std::size_t nodes, Eigen::Index solved,
                         const std::vector<double>& object_radii_mm, Eigen::MatrixXd& weights,
                         std::size_t& measured, std::size_t& kept_for_objects) {
  const auto n = static_cast<Eigen::Index>(g.n_u);
  weights.resize(n, solved);
  Eigen::VectorXd mask = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd broad = Eigen::VectorXd::Zero(n);
  for (Eigen::Index e = 0; e < n; ++e) {
    const std::vector<double> w =
        rings::ring_projection_weights(nodes, step_mm, g, static_cast<std::size_t>(e));
    for (Eigen::Index k = 0; k < solved; ++k) weights(e, k) = w[static_cast<std::size_t>(k)];
    if (r.usable[static_cast<std::size_t>(e)]) mask[e] = 1.0;
    broad[e] = r.broad[static_cast<std::size_t>(e)];
  }
  Eigen::MatrixXd projection(n, solved + 1);
  projection << mask.asDiagonal() * weights, mask;
  measured = 0;
  for (Eigen::Index k = 0; k < solved; ++k) measured += projection.col(k).squaredNorm() > 0.0;
  if (measured == 0) return Eigen::VectorXd::Zero(solved + 1);
  Eigen::MatrixXd normal = projection.transpose() * projection;
  const double scale = normal.topLeftCorner(solved, solved).trace() / static_cast<double>(solved);
  // Sum over k of (g[k] - 2 g[k+1] + g[k+2])^2, added term by term.
  const double stencil[3] = {1.0, -2.0, 1.0};
  for (Eigen::Index k = 0; k + 2 < solved; ++k) {
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) {
        normal(k + a, k + b) += kCurvatureWeight * scale * stencil[a] * stencil[b];
      }
    }
  }
  const std::vector<double> air = air_fraction_per_node(image, threshold, nodes);
  const double reach_mm = settings.scale_px * g.voxel_mm;
  kept_for_objects = 0;
  for (Eigen::Index k = 0; k < solved; ++k) {
    // The mirror pairs' objects are the image's, like air: held at no change.
    const bool object =
        rings::within_reach(object_radii_mm, static_cast<double>(k) * step_mm, reach_mm);
    kept_for_objects += object;
    const double hold = object ? 1.0 : air[static_cast<std::size_t>(k)];
    normal(k, k) += scale * (settings.air_weight * hold + kRidgeWeight);
  }
  return normal.ldlt().solve(projection.transpose() * broad);
}

}  // namespace

RingCorrection correct_rings_from_response(const Array& image, const Array& alpha,
                                           const Geometry& geometry,
                                           const std::vector<std::size_t>& dead_elements,
                                           const ResponseRingSettings& settings,
                                           const std::vector<double>& object_radii_mm) {
  rings::check_inputs("response ring correction", image, alpha, geometry);
  rings::validate("response ring correction", settings);
  rings::check_dead_elements("response ring correction", dead_elements, geometry.n_u);
  RingCorrection out = rings::unchanged(image, alpha, geometry.voxel_mm);
  if (!rings::all_finite(image)) return out;
  const double threshold = rings::air_threshold(image, settings.air_fraction);
  if (!(threshold > 0.0)) return out;

  const ResponseStructure structure =
      response_structure(alpha, geometry, dead_elements, settings.scale_px);
  if (structure.count < 2) return out;
  out.even_to_odd = even_to_odd(structure);
  if (out.even_to_odd == 0.0 || out.even_to_odd < settings.min_even_to_odd) return out;

  const rings::ProfileNodes at = rings::profile_nodes(image);
  if (at.solved < 3) return out;
  Eigen::MatrixXd weights;
  const Eigen::VectorXd gain =
      fit_gain(structure, image, geometry, settings, threshold, out.radius_step_mm, at.nodes,
               at.solved, object_radii_mm, weights, out.measured_radii, out.radii_kept_for_objects);
  if (out.measured_radii == 0) return out;
  out.scale_px = settings.scale_px;
  rings::move_gain_into_image(out, image, geometry, gain, weights, at.nodes,
                              settings.max_mean_response_change);
  return out;
}

}  // namespace riner
