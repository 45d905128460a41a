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
// The profile: nodes every half pixel of radius (an object's edge is sharp; the tangent rays'
// cusps place it to a fraction of an element), solved only within this many pixels of the
// radius of an element that shows an object, 0 elsewhere.
constexpr double kNodeStepPx = 0.5;
constexpr double kObjectMarginPx = 4.0;
// The fit's elements: those whose ray passes within this many pixels of an object element's
// (its cusp and flanks, which carry the object's shape) count fully; the other judged elements
// hold the profile's projection near no change with kHoldWeight (a real detector's broad even
// structure, a beam profile say, is no object: with full weight there the HTC disc's rim came
// out sharper than its edge, 3 speck pixels became 15).
constexpr double kEvidenceReachPx = 8.0;
constexpr double kHoldWeight = 0.1;
// The detector's own even part is noise as large as its odd part, which a profile with a node
// per element would copy into the image as fine rings. So the fit penalises the total variation
// of the corrected image's radial profile (the image's angular means plus the gain): an object's
// concentric structure is flat between sharp edges, while the field's share of it is blurred at
// them, so the gain that restores it is not flat (penalising the gain's own variation left the
// blur: a tube wall's inner edge -7.7% against -5.3% now, docs/history/RESULTS.md, issue 32).
// Its weight: the largest (of those tried) that leaves the weighted residual within this
// fraction of the noise (EvenEvidence::noise): a profile with about a node per element absorbs
// part of the noise, so the honest residual is below it (0.7: the tube-wall phantom at
// detectors of +-5% and +-25%, seeds 1-3; at 0.8 one of the six took a weight that shrank the
// wall by 5%).
constexpr double kResidualToNoise = 0.7;
constexpr double kSmallestVariationWeight = 1e-4;
constexpr int kVariationWeightsTried = 9;  // half decades up to 1
constexpr int kReweightingRounds = 60;
// |profile step| below this (1/mm) counts as this in the total variation's reweighting.
constexpr double kVariationFloor = 1e-5;

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

// The z for which normal noise at any of `tests` independent elements exceeds |z| with
// probability `false_alarm` (the union bound): the tail 2 (1 - Phi(z)) = false_alarm / tests.
double family_threshold(std::size_t tests, double false_alarm) {
  if (tests == 0) return 0.0;
  const double tail = false_alarm / static_cast<double>(tests);
  double lo = 0.0;
  double hi = 40.0;
  for (int i = 0; i < 100; ++i) {
    const double z = 0.5 * (lo + hi);
    (std::erfc(z / std::sqrt(2.0)) > tail ? lo : hi) = z;
  }
  return hi;
}

// Which elements' even structure is an object, and how much of it: the excess over the even
// part's level where it stands out and the odd part does not, grown to the neighbours.
struct EvenEvidence {
  std::vector<char> judged;  // paired with a mirror far enough away to tell
  std::vector<char> object;
  std::vector<double> target;  // every judged element's even part above the level
  std::size_t count = 0;
  double largest_sigmas = 0.0;
  double sigmas = 0.0;  // the threshold: min_sigmas, or the family's over the judged elements
  // The detector's noise in the even part: the odd part's robust spread over the judged
  // elements, or the even part's own element-to-element roughness where that is larger.
  double noise = 0.0;
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
  for (std::size_t e = 0; e < n; ++e) {
    ev.judged[e] = parts.paired[e] && parts.mirror_gap[e] > kMirrorGapWindows * s.window_elements;
  }
  const auto judged = static_cast<std::size_t>(std::count(ev.judged.begin(), ev.judged.end(), 1));
  ev.sigmas = std::max(s.min_sigmas, family_threshold(judged, s.max_false_alarm));
  std::vector<char> seed(n, 0);
  for (std::size_t e = 0; e < n; ++e) {
    if (!ev.judged[e]) continue;
    const double excess = std::fabs(even[e] - level);
    if (excess <= kSmallestStructure || excess <= ev.sigmas * noise[e]) continue;
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
  std::vector<double> odd_judged;
  for (std::size_t e = 0; e < n; ++e) {
    if (ev.object[e]) ++ev.count;
    if (!ev.judged[e]) continue;
    // Unsmoothed: the cusps of an object's projection at its tangent rays place its edges.
    ev.target[e] = parts.even[e] - level;
    odd_judged.push_back(std::fabs(parts.odd[e]));
  }
  if (!odd_judged.empty()) ev.noise = util::kMadToSigma * util::quantile(odd_judged, 0.5);
  // The even part's own roughness from element to element, which no object's projection has
  // (it is smooth but at a few cusps, which the median passes over): a detector whose structure
  // is even (modules laid out symmetrically about the axis) is noise of that size to the fit.
  std::vector<double> curvature;
  for (std::size_t e = 1; e + 1 < n; ++e) {
    if (ev.judged[e - 1] && ev.judged[e] && ev.judged[e + 1]) {
      curvature.push_back(std::fabs(parts.even[e - 1] - 2.0 * parts.even[e] + parts.even[e + 1]));
    }
  }
  if (!curvature.empty()) {
    // A second difference of white noise has sqrt(6) times its spread.
    const double rough = util::kMadToSigma * util::quantile(curvature, 0.5) / std::sqrt(6.0);
    ev.noise = std::max(ev.noise, rough);
  }
  return ev;
}

// The distances from the axis of the rays of the elements that show an object.
std::vector<double> object_radii(const EvenEvidence& ev, const std::vector<double>& distance) {
  std::vector<double> radii;
  for (std::size_t e = 0; e < ev.object.size(); ++e) {
    if (ev.object[e]) radii.push_back(std::fabs(distance[e]));
  }
  return radii;
}

// The total variation the fit penalises: between neighbouring nodes of which at least one is
// solved (an unsolved node gains nothing), of the image's profile plus the gain.
struct ProfileVariation {
  Eigen::MatrixXd difference;  // a row per neighbouring pair, a column per solved node
  Eigen::VectorXd image_step;  // the image profile's own step across each pair
};

ProfileVariation profile_variation(const std::vector<Eigen::Index>& at, Eigen::Index solved,
                                   const std::vector<double>& image_profile) {
  std::vector<Eigen::Index> column(static_cast<std::size_t>(solved) + 1, -1);
  for (std::size_t c = 0; c < at.size(); ++c) {
    column[static_cast<std::size_t>(at[c])] = static_cast<Eigen::Index>(c);
  }
  std::vector<std::size_t> pairs;  // the lower node of each pair
  for (std::size_t k = 0; k < static_cast<std::size_t>(solved); ++k) {
    if (column[k] >= 0 || column[k + 1] >= 0) pairs.push_back(k);
  }
  ProfileVariation v{Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(pairs.size()),
                                           static_cast<Eigen::Index>(at.size())),
                     Eigen::VectorXd::Zero(static_cast<Eigen::Index>(pairs.size()))};
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    const std::size_t k = pairs[i];
    const auto row = static_cast<Eigen::Index>(i);
    if (column[k] >= 0) v.difference(row, column[k]) = -1.0;
    if (column[k + 1] >= 0) v.difference(row, column[k + 1]) = 1.0;
    v.image_step[row] = image_profile[k + 1] - image_profile[k];
  }
  return v;
}

// Least squares of `a` (the used nodes' projections, rows weighted) against `target`, plus
// `weight` times the total variation `v` (reweighted least squares).
Eigen::VectorXd fit_with_variation(const Eigen::MatrixXd& a, const Eigen::VectorXd& target,
                                   double weight, const ProfileVariation& v) {
  const Eigen::Index k = a.cols();
  const Eigen::MatrixXd normal = a.transpose() * a;
  const Eigen::VectorXd rhs = a.transpose() * target;
  const double scale = normal.trace() / static_cast<double>(k);
  const Eigen::MatrixXd ridge = 1e-6 * scale * Eigen::MatrixXd::Identity(k, k);
  Eigen::VectorXd g = (normal + 1e3 * ridge).ldlt().solve(rhs);
  for (int round = 0; round < kReweightingRounds; ++round) {
    const Eigen::VectorXd reweight =
        (v.difference * g + v.image_step).array().abs().max(kVariationFloor).inverse().matrix();
    const Eigen::MatrixXd penalty = v.difference.transpose() * reweight.asDiagonal() * v.difference;
    const Eigen::VectorXd pull = v.difference.transpose() * (reweight.asDiagonal() * v.image_step);
    g = (normal + weight * scale * penalty + ridge).ldlt().solve(rhs - weight * scale * pull);
  }
  return g;
}

// The profile (its gain to the image per solved node) and every element's projection weights
// on the solved nodes; `used`: how many nodes it may use.
Eigen::VectorXd fit_gain(const EvenEvidence& ev, const Geometry& g,
                         const std::vector<double>& distance, double step_mm, std::size_t nodes,
                         Eigen::Index solved, const std::vector<double>& image_profile,
                         Eigen::MatrixXd& weights, std::size_t& used) {
  const auto n = static_cast<Eigen::Index>(g.n_u);
  weights.resize(n, solved);
  for (Eigen::Index e = 0; e < n; ++e) {
    const std::vector<double> row =
        rings::ring_projection_weights(nodes, step_mm, g, static_cast<std::size_t>(e));
    for (Eigen::Index k = 0; k < solved; ++k) weights(e, k) = row[static_cast<std::size_t>(k)];
  }
  const std::vector<double> objects = object_radii(ev, distance);
  std::vector<Eigen::Index> at;
  for (Eigen::Index k = 0; k < solved; ++k) {
    const double radius = static_cast<double>(k) * step_mm;
    if (rings::within_reach(objects, radius, kObjectMarginPx * g.voxel_mm)) at.push_back(k);
  }
  used = at.size();
  Eigen::VectorXd gain = Eigen::VectorXd::Zero(solved);
  if (at.size() < 2) return gain;
  // Rows: the judged elements whose rays reach a used node (the others see no profile).
  std::vector<Eigen::Index> rows;
  for (Eigen::Index e = 0; e < n; ++e) {
    if (!ev.judged[static_cast<std::size_t>(e)]) continue;
    bool reaches = false;
    for (Eigen::Index k : at) reaches = reaches || weights(e, k) > 0.0;
    if (reaches) rows.push_back(e);
  }
  if (rows.empty()) return gain;
  const auto m = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd a(m, static_cast<Eigen::Index>(at.size()));
  Eigen::VectorXd target(m);
  for (Eigen::Index r = 0; r < m; ++r) {
    const auto e = static_cast<std::size_t>(rows[static_cast<std::size_t>(r)]);
    const bool full =
        rings::within_reach(objects, std::fabs(distance[e]), kEvidenceReachPx * g.voxel_mm);
    const double w = full ? 1.0 : kHoldWeight;
    for (std::size_t k = 0; k < at.size(); ++k) {
      a(r, static_cast<Eigen::Index>(k)) = w * weights(rows[static_cast<std::size_t>(r)], at[k]);
    }
    target[r] = full ? ev.target[e] : 0.0;
  }
  const ProfileVariation variation = profile_variation(at, solved, image_profile);
  const double allowed = kResidualToNoise * ev.noise * std::sqrt(static_cast<double>(m));
  Eigen::VectorXd best;
  for (int i = 0; i < kVariationWeightsTried; ++i) {
    const double weight = kSmallestVariationWeight * std::pow(10.0, 0.5 * i);
    Eigen::VectorXd fit = fit_with_variation(a, target, weight, variation);
    if (best.size() > 0 && (a * fit - target).norm() > allowed) break;
    best = std::move(fit);
  }
  for (std::size_t k = 0; k < at.size(); ++k) gain[at[k]] = best[static_cast<Eigen::Index>(k)];
  return gain;
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
  const std::vector<double> distance = column_ray_distances(geometry);
  const MirrorParts parts = mirror_parts(offsets.offset, offsets.usable, distance);
  const EvenEvidence evidence = even_evidence(parts, settings);
  out.elements_moved = evidence.count;
  out.largest_even_sigmas = evidence.largest_sigmas;
  out.even_sigmas_needed = evidence.sigmas;
  if (evidence.count == 0) return out;
  out.object_radii_mm = object_radii(evidence, distance);

  out.radius_step_mm = kNodeStepPx * geometry.voxel_mm;
  const rings::ProfileNodes at = rings::profile_nodes(image, kNodeStepPx);
  if (at.solved < 3) return out;
  const std::vector<double> image_profile =
      rings::PixelRadii(image.shape[0], image.shape[1], kNodeStepPx)
          .angular_means(image.data, at.nodes);
  Eigen::MatrixXd weights;
  const Eigen::VectorXd gain = fit_gain(evidence, geometry, distance, out.radius_step_mm, at.nodes,
                                        at.solved, image_profile, weights, out.measured_radii);
  if (out.measured_radii == 0) return out;
  rings::move_gain_into_image(out, image, geometry, gain, weights, at.nodes,
                              settings.max_mean_response_change);
  return out;
}

}  // namespace riner
