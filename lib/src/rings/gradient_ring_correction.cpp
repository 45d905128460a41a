#include <algorithm>
#include <cmath>

#include "riner/error.hpp"
#include "riner/ring_correction.hpp"
#include "rings/radial.hpp"
#include "rings/ring_profile.hpp"
#include "rings/ring_settings.hpp"
#include "util/robust_statistics.hpp"

namespace riner {

namespace {

// A circle with fewer usable points than this (near the grid's corners) is not measured.
constexpr std::size_t kMinPoints = 32;
// A slope counts as a ring only where it stands this many of its standard errors from 0 (the
// median's, over the independent pixels of the circle's flattest half, about pi r of them):
// below, it is the object's own pixels (near the axis, where a circle holds a few of them, an
// edge crossing it makes its changes two-sided), which the running sum would paint in as rings:
// the tooth's centre got a dark dot of -0.0011/mm, a third of the value there. 0.5: the smallest
// of 0.25-3 that removed it; DeepLesion -0.003 dB (docs/history/RESULTS.md, issue 29).
constexpr double kSlopeStandardErrors = 0.5;
constexpr double kMedianStandardError = 1.2533;  // times sigma / sqrt(n), for normal noise

// The image sampled on circles about the rotation axis (the grid's centre): one row of
// `angles` bilinear samples per radius of whole pixels; NaN where a sample leaves the grid.
struct PolarSamples {
  std::size_t radii = 0;
  std::size_t angles = 0;
  std::vector<float> values;  // [radius][angle]
  float at(std::size_t r, std::size_t a) const { return values[r * angles + a]; }
};

PolarSamples sample_circles(const Array& image) {
  const std::size_t ny = image.shape[0];
  const std::size_t nx = image.shape[1];
  const double cx = 0.5 * static_cast<double>(nx - 1);
  const double cy = 0.5 * static_cast<double>(ny - 1);
  PolarSamples s;
  s.radii = static_cast<std::size_t>(std::ceil(std::hypot(cx, cy))) + 1;
  // About four samples per pixel of the largest circle's circumference.
  s.angles = std::max<std::size_t>(256, 8 * std::max(nx, ny));
  s.values.assign(s.radii * s.angles, std::nanf(""));
  for (std::size_t r = 0; r < s.radii; ++r) {
    for (std::size_t a = 0; a < s.angles; ++a) {
      const double phi = 2.0 * M_PI * static_cast<double>(a) / static_cast<double>(s.angles);
      const double col = cx + static_cast<double>(r) * std::cos(phi);
      const double row = cy - static_cast<double>(r) * std::sin(phi);
      if (col < 0.0 || row < 0.0 || col > static_cast<double>(nx - 1) ||
          row > static_cast<double>(ny - 1))
        continue;
      const auto k = std::min(static_cast<std::size_t>(col), nx - 2);
      const auto i = std::min(static_cast<std::size_t>(row), ny - 2);
      const double u = col - static_cast<double>(k);
      const double v = row - static_cast<double>(i);
      s.values[r * s.angles + a] =
          static_cast<float>((1 - v) * ((1 - u) * image(i, k) + u * image(i, k + 1)) +
                             v * ((1 - u) * image(i + 1, k) + u * image(i + 1, k + 1)));
    }
  }
  return s;
}

// The ring's slope from radius r to r + 1: the median change over the circle's flattest
// points, 0 where that is within kSlopeStandardErrors of 0. False when too few points lie
// inside the grid.
bool ring_slope(const PolarSamples& s, std::size_t r, double flat_fraction, double& slope) {
  std::vector<float> change;
  std::vector<float> along;  // how much the image changes along the circle at that point
  for (std::size_t a = 0; a < s.angles; ++a) {
    const std::size_t prev = (a + s.angles - 1) % s.angles;
    const std::size_t next = (a + 1) % s.angles;
    const float d = s.at(r + 1, a) - s.at(r, a);
    const float t = std::max(std::fabs(s.at(r, next) - s.at(r, prev)),
                             std::fabs(s.at(r + 1, next) - s.at(r + 1, prev)));
    if (!std::isfinite(d) || !std::isfinite(t)) continue;
    change.push_back(d);
    along.push_back(t);
  }
  if (change.size() < kMinPoints) return false;
  std::vector<float> sorted = along;
  const auto cut =
      static_cast<std::ptrdiff_t>(flat_fraction * static_cast<double>(sorted.size() - 1));
  std::nth_element(sorted.begin(), sorted.begin() + cut, sorted.end());
  const float limit = sorted[static_cast<std::size_t>(cut)];
  std::vector<float> flat;
  for (std::size_t j = 0; j < change.size(); ++j) {
    if (along[j] <= limit) flat.push_back(change[j]);
  }
  const auto mid = flat.begin() + static_cast<std::ptrdiff_t>(flat.size() / 2);
  std::nth_element(flat.begin(), mid, flat.end());
  slope = *mid;
  std::vector<double> deviation(flat.size());
  for (std::size_t j = 0; j < flat.size(); ++j) deviation[j] = std::fabs(flat[j] - slope);
  const double sigma = util::kMadToSigma * util::quantile(deviation, 0.5);
  const double independent =
      std::min(static_cast<double>(flat.size()), M_PI * std::max(static_cast<double>(r), 0.5));
  if (std::fabs(slope) <
      kSlopeStandardErrors * kMedianStandardError * sigma / std::sqrt(independent))
    slope = 0.0;
  return true;
}

// values minus their running median over 2 half_width + 1 nodes, mirrored at both ends. A
// feature narrower than half_width goes; a step (the edge of a disc about the axis) stays, where
// a Gaussian high-pass would leave rings on both sides of it (docs/history/RESULTS.md, issue 13).
// Within half_width of the axis the window shrinks to the node's radius (least_half_width at
// least): mirrored there, a wide window takes the object's own radial trend near the axis for
// a ring (the tooth's centre 0.70 -> 1.28 sigma at 30 px; issue 29).
std::vector<double> high_pass(const std::vector<double>& values, std::size_t half_width,
                              std::size_t least_half_width) {
  const auto n = static_cast<std::ptrdiff_t>(values.size());
  std::vector<double> out(values.size());
  std::vector<double> window;
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const auto h = static_cast<std::ptrdiff_t>(std::clamp(
        static_cast<std::size_t>(i), std::min(least_half_width, half_width), half_width));
    window.resize(static_cast<std::size_t>(2 * h + 1));
    for (std::ptrdiff_t k = -h; k <= h; ++k) {
      window[static_cast<std::size_t>(k + h)] =
          values[static_cast<std::size_t>(rings::mirrored(i + k, n))];
    }
    const auto mid = window.begin() + h;
    std::nth_element(window.begin(), mid, window.end());
    const auto at = static_cast<std::size_t>(i);
    out[at] = values[at] - *mid;
  }
  return out;
}

}  // namespace

RingCorrection correct_rings_from_gradient(const Array& image, const Array& alpha,
                                           const Geometry& geometry,
                                           const GradientRingSettings& settings,
                                           const std::vector<double>& object_radii_mm) {
  rings::check_inputs("gradient ring correction", image, alpha, geometry);
  rings::validate("gradient ring correction", settings);
  RingCorrection out = rings::unchanged(image, alpha, geometry.voxel_mm);
  if (!rings::all_finite(image)) return out;
  const std::size_t ny = image.shape[0];
  const std::size_t nx = image.shape[1];
  if (ny < 2 || nx < 2) return out;

  const PolarSamples circles = sample_circles(image);
  std::vector<double> ring(circles.radii, 0.0);
  for (std::size_t r = 0; r + 1 < circles.radii; ++r) {
    double slope = 0.0;
    // The circle of radius 0 is one point, flat by definition: the flattest points would be one
    // side of any edge through the axis, and the axis would get a dot of half the edge's step.
    const double fraction = r == 0 ? 1.0 : settings.flat_fraction;
    if (ring_slope(circles, r, fraction, slope)) ++out.measured_radii;
    ring[r + 1] = ring[r] + slope;
  }
  if (out.measured_radii == 0) return out;
  const double scale_px = settings.scale_px_for(std::max(ny, nx));
  out.profile = high_pass(ring, static_cast<std::size_t>(std::lround(scale_px)),
                          static_cast<std::size_t>(GradientRingSettings::kScaleAt256Px));
  out.scale_px = scale_px;
  const double reach_mm = scale_px * geometry.voxel_mm;
  for (std::size_t k = 0; k < out.profile.size(); ++k) {
    const double radius_mm = static_cast<double>(k) * out.radius_step_mm;
    if (!rings::within_reach(object_radii_mm, radius_mm, reach_mm)) continue;
    out.profile[k] = 0.0;
    ++out.radii_kept_for_objects;
  }
  out.profile.push_back(out.profile.back());  // a spare node for the interpolation
  if (rings::fold_into_alpha(out,
                             rings::ring_projections(out.profile, out.radius_step_mm, geometry),
                             settings.max_mean_response_change)) {
    rings::subtract_profile(out, image, geometry);
  }
  out.profile.pop_back();
  return out;
}

}  // namespace riner
