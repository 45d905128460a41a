#include <algorithm>
#include <cmath>
#include <string>

#include "riner/error.hpp"
#include "riner/rays.hpp"
#include "riner/ring_correction.hpp"
#include "rings/radial.hpp"
#include "rings/ring_profile.hpp"
#include "rings/ring_settings.hpp"

namespace riner {

namespace {

// Refinement passes: each finds the air again in the image with the previous ring removed, so
// air that a strong ring had pushed above the threshold comes back.
constexpr int kPasses = 3;
// Fewer air pixels than this in the whole image: nothing to reference the rings to.
constexpr std::size_t kMinAirPixels = 64;

float median_of(std::vector<float>& values) {
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

// Pixels of `mask` whose 4-neighbourhood, `steps` times over, holds only mask pixels; outside
// the grid counts as air (the region beyond it is empty by definition).
std::vector<char> erode(std::vector<char> mask, std::size_t ny, std::size_t nx, int steps) {
  std::vector<char> next(mask.size());
  for (int s = 0; s < steps; ++s) {
    for (std::size_t i = 0; i < ny; ++i) {
      for (std::size_t k = 0; k < nx; ++k) {
        const std::size_t p = i * nx + k;
        next[p] = mask[p] && (i == 0 || mask[p - nx]) && (i + 1 == ny || mask[p + nx]) &&
                  (k == 0 || mask[p - 1]) && (k + 1 == nx || mask[p + 1]);
      }
    }
    mask.swap(next);
  }
  return mask;
}

// Pixels of `mask` joined to the grid's edge through mask pixels (4-neighbourhood): the air
// around the object, which outside the grid continues.
std::vector<char> joined_to_edge(const std::vector<char>& mask, std::size_t ny, std::size_t nx) {
  std::vector<char> out(mask.size(), 0);
  std::vector<std::size_t> stack;
  const auto visit = [&](std::size_t p) {
    if (mask[p] && !out[p]) {
      out[p] = 1;
      stack.push_back(p);
    }
  };
  for (std::size_t k = 0; k < nx; ++k) {
    visit(k);
    visit((ny - 1) * nx + k);
  }
  for (std::size_t i = 0; i < ny; ++i) {
    visit(i * nx);
    visit(i * nx + nx - 1);
  }
  while (!stack.empty()) {
    const std::size_t p = stack.back();
    stack.pop_back();
    const std::size_t i = p / nx;
    const std::size_t k = p % nx;
    if (i > 0) visit(p - nx);
    if (i + 1 < ny) visit(p + nx);
    if (k > 0) visit(p - 1);
    if (k + 1 < nx) visit(p + 1);
  }
  return out;
}

}  // namespace

RingCorrection correct_rings_from_air(const Array& image, const Array& alpha,
                                      const Geometry& geometry, const AirRingSettings& settings) {
  rings::check_inputs("air ring correction", image, alpha, geometry);
  rings::validate("air ring correction", settings);
  RingCorrection out = rings::unchanged(image, alpha, 0.5 * geometry.voxel_mm);
  const std::size_t ny = image.shape[0];
  const std::size_t nx = image.shape[1];
  const std::size_t n = image.size();
  if (!rings::all_finite(image)) return out;

  const double threshold = rings::air_threshold(image, settings.air_fraction);
  if (!(threshold > 0.0)) return out;

  // Each pixel in the bin of its nearest node (medians need one bin per pixel).
  const rings::PixelRadii radii(ny, nx, out.radius_step_mm / geometry.voxel_mm);
  std::vector<std::size_t> bin(n);
  for (std::size_t p = 0; p < n; ++p) bin[p] = radii.nearest(p);
  const std::size_t bins = radii.nearest_nodes();

  std::vector<double> profile(bins + 1, 0.0);  // one spare node for the interpolation
  std::vector<std::vector<float>> air_by_bin(bins);
  std::vector<float> air_values;
  std::vector<char> measured(bins, 0);
  for (int pass = 0; pass < kPasses; ++pass) {
    std::vector<char> air(n);
    for (std::size_t p = 0; p < n; ++p) air[p] = image.data[p] - profile[bin[p]] < threshold;
    if (settings.reaches_edge) air = joined_to_edge(air, ny, nx);
    air = erode(std::move(air), ny, nx, settings.erosion_px);
    air_values.clear();
    for (auto& values : air_by_bin) values.clear();
    for (std::size_t p = 0; p < n; ++p) {
      if (!air[p]) continue;
      air_values.push_back(image.data[p] - static_cast<float>(profile[bin[p]]));
      air_by_bin[bin[p]].push_back(image.data[p]);
    }
    out.air_pixels = air_values.size();
    if (air_values.size() < kMinAirPixels) {
      std::fill(profile.begin(), profile.end(), 0.0);
      std::fill(measured.begin(), measured.end(), 0);
      break;
    }
    const double level = median_of(air_values);
    std::vector<double> raw(bins, 0.0);
    for (std::size_t b = 0; b < bins; ++b) {
      measured[b] = air_by_bin[b].size() >= static_cast<std::size_t>(settings.min_pixels);
      raw[b] = measured[b] ? median_of(air_by_bin[b]) - level : 0.0;
    }
    // The rings training leaves are broad; single bins' medians carry pixel noise that would
    // otherwise come back as fine rings.
    profile = rings::gaussian_smooth(raw, settings.smoothing_bins, rings::Ends::kCut, &measured);
    profile.push_back(0.0);
  }

  out.measured_radii = static_cast<std::size_t>(std::count(measured.begin(), measured.end(), 1));
  out.profile = std::move(profile);
  if (out.measured_radii > 0 &&
      rings::fold_into_alpha(out,
                             rings::ring_projections(out.profile, out.radius_step_mm, geometry),
                             settings.max_mean_response_change)) {
    for (std::size_t p = 0; p < n; ++p) {
      out.image.data[p] = image.data[p] - static_cast<float>(out.profile[bin[p]]);
    }
  }
  out.profile.pop_back();
  return out;
}

}  // namespace riner
