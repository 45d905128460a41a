#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "riner/rays.hpp"
#include "riner/ring_correction.hpp"
#include "rings/radial.hpp"
#include "rings/ring_profile.hpp"
#include "rings/ring_settings.hpp"
#include "util/robust_statistics.hpp"

namespace riner {

namespace {

// Even structure below this (in -ln alpha) is not worth moving, whatever the noise.
constexpr double kSmallestStructure = 1e-4;
// An object's even structure stands this many times above the odd part beside it; a detector's
// bad element makes them alike.
constexpr double kEvenOverOdd = 2.0;
// Evidence needs an element's mirror this many noise windows away: nearer the axis a
// detector's or a beam's structure across the centre reads as even (on wood_neutron a plateau
// 60 elements wide on the axis, docs/history/RESULTS.md).
constexpr double kMirrorGapWindows = 4.0;
// Elements that could tell but show no object hold the profile's projection near no change,
// with this weight against the evidence's; a small ridge keeps radii no ray reaches at 0.
constexpr double kHoldWeight = 0.1;
constexpr double kRidgeWeight = 1e-3;

// The fractional element whose ray lies at distance x from the axis (distances run monotonically
// across the detector), or -1 when x is beyond the detector.
double element_at(const std::vector<double>& distance, double x) {
  const double sign = distance.back() >= distance.front() ? 1.0 : -1.0;
  const double t = sign * x;
  if (t < sign * distance.front() || t > sign * distance.back()) return -1.0;
  const auto it = std::lower_bound(distance.begin(), distance.end(), x,
                                   [sign](double a, double b) { return sign * a < sign * b; });
  const auto hi = static_cast<std::size_t>(it - distance.begin());
  if (hi == 0) return 0.0;
  const std::size_t lo = hi - 1;
  const double span = sign * (distance[hi] - distance[lo]);
  return static_cast<double>(lo) + (span > 0.0 ? (t - sign * distance[lo]) / span : 0.0);
}

// Calls f(k) for every element k within `radius` of element e, of n.
template <typename F>
void for_each_near(std::size_t e, std::size_t radius, std::size_t n, F f) {
  const std::size_t last = std::min(n - 1, e + radius);
  for (std::size_t k = e > radius ? e - radius : 0; k <= last; ++k) f(k);
}

// -ln(alpha) split about the axis: even = (own + mirror) / 2, odd = (own - mirror) / 2, the
// mirror interpolated between the two usable elements around distance -d.
struct MirrorParts {
  std::vector<char> paired;
  std::vector<double> even, odd;
  // Elements between an element and its mirror. Where the mirror lies within the noise window
  // (near the axis), a detector's smooth structure across the centre reads as even: no evidence.
  std::vector<double> mirror_gap;
};

MirrorParts mirror_parts(const std::vector<double>& offset, const std::vector<char>& usable,
                         const std::vector<double>& distance) {
  const std::size_t n = offset.size();
  MirrorParts p{std::vector<char>(n, 0), std::vector<double>(n, 0.0), std::vector<double>(n, 0.0),
                std::vector<double>(n, 0.0)};
  for (std::size_t e = 0; e < n; ++e) {
    if (!usable[e]) continue;
    const double at = element_at(distance, -distance[e]);
    if (at < 0.0) continue;
    const auto lo = static_cast<std::size_t>(at);
    const std::size_t hi = std::min(lo + 1, n - 1);
    const double w = at - static_cast<double>(lo);
    if (!usable[lo] || (w > 0.0 && !usable[hi])) continue;
    const double mirror = (1.0 - w) * offset[lo] + w * offset[hi];
    p.paired[e] = 1;
    p.mirror_gap[e] = std::fabs(at - static_cast<double>(e));
    p.even[e] = 0.5 * (offset[e] + mirror);
    p.odd[e] = 0.5 * (offset[e] - mirror);
  }
  return p;
}

// The median of |values| over the paired elements within `window` of each paired element.
std::vector<double> running_median_abs(const std::vector<double>& values,
                                       const std::vector<char>& paired, int window) {
  const std::size_t n = values.size();
  std::vector<double> out(n, 0.0);
  std::vector<double> near;
  for (std::size_t e = 0; e < n; ++e) {
    if (!paired[e]) continue;
    near.clear();
    for_each_near(e, static_cast<std::size_t>(window), n, [&](std::size_t k) {
      if (paired[k]) near.push_back(std::fabs(values[k]));
    });
    out[e] = util::quantile(near, 0.5);
  }
  return out;
}

// Which elements' even structure is an object, and how much of it: the excess over the even
// part's level where it stands out and the odd part does not, grown to the neighbours.
struct EvenEvidence {
  std::vector<char> judged;  // paired with a mirror far enough away to tell
  std::vector<char> object;
  std::vector<double> target;  // -ln(alpha) the profile's projection should take away
  std::size_t count = 0;
  double largest_sigmas = 0.0;
};

EvenEvidence even_evidence(const MirrorParts& parts, const MirrorRingSettings& s) {
  const std::size_t n = parts.paired.size();
  EvenEvidence ev{std::vector<char>(n, 0), std::vector<char>(n, 0), std::vector<double>(n, 0.0)};
  const std::vector<double> even =
      rings::gaussian_smooth(parts.even, s.smoothing_elements, rings::Ends::kCut, &parts.paired);
  const std::vector<double> odd =
      rings::gaussian_smooth(parts.odd, s.smoothing_elements, rings::Ends::kCut, &parts.paired);
  // The odd part's noise: its robust spread nearby (it has no level: a constant is even).
  std::vector<double> noise = running_median_abs(odd, parts.paired, s.window_elements);
  for (double& v : noise) v *= util::kMadToSigma;
  std::vector<double> paired_even;
  for (std::size_t e = 0; e < n; ++e) {
    if (parts.paired[e]) paired_even.push_back(even[e]);
  }
  if (paired_even.empty()) return ev;
  const double level = util::quantile(paired_even, 0.5);
  // Around each element (its grow neighbourhood), the even part's excess and the odd part as
  // root mean squares: one bad element makes both alike, an object only the even one.
  const auto grow = static_cast<std::size_t>(s.grow_elements);
  const auto near_rms = [&](const std::vector<double>& v, double minus, std::size_t e) {
    double sum = 0.0;
    double count = 0.0;
    for_each_near(e, grow, n, [&](std::size_t k) {
      if (!parts.paired[k]) return;
      sum += (v[k] - minus) * (v[k] - minus);
      count += 1.0;
    });
    return count > 0.0 ? std::sqrt(sum / count) : 0.0;
  };
  std::vector<char> seed(n, 0);
  for (std::size_t e = 0; e < n; ++e) {
    if (!parts.paired[e] || parts.mirror_gap[e] <= kMirrorGapWindows * s.window_elements) continue;
    ev.judged[e] = 1;
    const double excess = std::fabs(even[e] - level);
    if (excess <= kSmallestStructure || excess <= s.min_sigmas * noise[e]) continue;
    if (near_rms(even, level, e) <= kEvenOverOdd * near_rms(odd, 0.0, e)) continue;
    seed[e] = 1;
    if (noise[e] > 0.0) ev.largest_sigmas = std::max(ev.largest_sigmas, excess / noise[e]);
  }
  for (std::size_t e = 0; e < n; ++e) {
    if (!seed[e]) continue;
    for_each_near(e, grow, n, [&](std::size_t k) {
      if (ev.judged[k]) ev.object[k] = 1;
    });
  }
  for (std::size_t e = 0; e < n; ++e) {
    if (!ev.object[e]) continue;
    ev.target[e] = even[e] - level;
    ++ev.count;
  }
  return ev;
}

// Weighted least squares of the profile's projections against the target: weight 1 where the
// evidence is, kHoldWeight (target 0) on the other judged elements, 0 on the rest (no evidence
// either way: their alpha takes whatever the profile projects there). Returns the
// image's gain per solved node; `weights` gets every element's projection weights on them.
Eigen::VectorXd fit_gain(const EvenEvidence& ev, const Geometry& g, double step_mm,
                         std::size_t nodes, Eigen::Index solved, Eigen::MatrixXd& weights,
                         std::size_t& measured) {
  const auto n = static_cast<Eigen::Index>(g.n_u);
  weights.resize(n, solved);
  Eigen::VectorXd w = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd target = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd object = Eigen::VectorXd::Zero(n);
  for (Eigen::Index e = 0; e < n; ++e) {
    const auto i = static_cast<std::size_t>(e);
    const std::vector<double> row = rings::ring_projection_weights(nodes, step_mm, g, i);
    for (Eigen::Index k = 0; k < solved; ++k) weights(e, k) = row[static_cast<std::size_t>(k)];
    w[e] = ev.object[i] ? 1.0 : ev.judged[i] ? kHoldWeight : 0.0;
    target[e] = ev.target[i];
    object[e] = ev.object[i] ? 1.0 : 0.0;
  }
  const Eigen::MatrixXd weighted = w.asDiagonal() * weights;
  // Radii some object element's ray reaches.
  measured = static_cast<std::size_t>(((weights.transpose() * object).array() > 0.0).count());
  Eigen::MatrixXd normal = weighted.transpose() * weighted;
  const double scale = normal.trace() / static_cast<double>(solved);
  normal.diagonal().array() += kRidgeWeight * scale;
  return normal.ldlt().solve(weighted.transpose() * w.asDiagonal() * target);
}

}  // namespace

RingCorrection correct_rings_from_mirrors(const Array& image, const Array& alpha,
                                          const Geometry& geometry,
                                          const std::vector<std::size_t>& dead_elements,
                                          const MirrorRingSettings& settings) {
  rings::check_inputs("mirror ring correction", image, alpha, geometry);
  rings::validate("mirror ring correction", settings);
  rings::check_dead_elements("mirror ring correction", dead_elements, geometry.n_u);
  RingCorrection out = rings::unchanged(image, alpha, geometry.voxel_mm);
  if (!rings::all_finite(image) || geometry.n_u < 2) return out;
  const rings::ResponseOffsets offsets = rings::response_offsets(alpha, dead_elements);
  const MirrorParts parts =
      mirror_parts(offsets.offset, offsets.usable, column_ray_distances(geometry));
  const EvenEvidence evidence = even_evidence(parts, settings);
  out.elements_moved = evidence.count;
  out.largest_even_sigmas = evidence.largest_sigmas;
  if (evidence.count == 0) return out;

  const rings::ProfileNodes at = rings::profile_nodes(image);
  if (at.solved < 3) return out;
  Eigen::MatrixXd weights;
  const Eigen::VectorXd gain = fit_gain(evidence, geometry, out.radius_step_mm, at.nodes, at.solved,
                                        weights, out.measured_radii);
  if (out.measured_radii == 0) return out;
  rings::move_gain_into_image(out, image, geometry, gain, weights, at.nodes,
                              settings.max_mean_response_change);
  return out;
}

}  // namespace riner
