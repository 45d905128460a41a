#include "riner/quality.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include "metrics/gradient_magnitude.hpp"
#include "metrics/radial_profile.hpp"
#include "riner/error.hpp"
#include "riner/metrics.hpp"
#include "rings/radial.hpp"
#include "util/gaussian_blur.hpp"
#include "util/robust_statistics.hpp"

namespace riner {

namespace {

constexpr double kSpeckSigmas = 6.0;
constexpr double kEdgePercentile = 0.99;
// The FBP's edges stand out of its noise at a scale where the 99th percentile of its gradient
// is this many times the median (mostly flat pixels: noise). White noise alone reads 2.6; the
// shared real scans' FBPs 15-30 at 1 px, the 1100-column faint square's 3.9 (its pixel noise
// is larger than the square's step), 27 at 4 px.
constexpr double kEdgesOverNoise = 10.0;
constexpr std::array<double, 4> kEdgeScalesPx = {1.0, 2.0, 4.0, 8.0};
constexpr double kLostBlurPx = 2.0;
constexpr double kLostAirShareOfHigh = 0.1;  // of the image's 99.5th percentile
constexpr double kLostObjectSigmas = 5.0;
constexpr double kLostShownShare = 0.25;  // of what the FBP shows
constexpr std::size_t kLostMinAirPixels = 100;
// A lost region is object clearly where it is wide or stands high: FBP's streaks and the arcs
// of its rings in the air pass 5 sigmas by a little over a few pixels (a ring-free simulated
// head at 1e7 photons: 4 blobs of 4-15 pixels at 5.5-6.8 sigmas), a corner cut off a faint
// sample or a wide ring's arc of the sample removed spans dozens (neutron360's sorting at a
// window of 31: 159 and 68 pixels, up to 10 sigmas).
constexpr std::size_t kLostWideRegionPixels = 20;
constexpr double kLostHighSigmas = 10.0;
// thin_arc_radii: a ring of one element blurred by kLostBlurPx is 4.7 px wide at half its height.
constexpr double kLostArcWidthPx = 5.5;
constexpr double kLostArcLengthToWidth = 4.0;
constexpr double kLostArcLeastRadiusPx = 8.0;

// "at least 16 x 16"
std::string smallest_sides() {
  const std::string side = std::to_string(kQualitySmallestSide);
  return "at least " + side + " x " + side;
}

void require_2d(const Array& a, const char* what) {
  if (a.rank() != 2 || a.shape[0] < kQualitySmallestSide || a.shape[1] < kQualitySmallestSide)
    throw InputError(std::string(what) + " must be a 2D image of " + smallest_sides());
}

// A 2D image, or a volume whose axial slices are images.
void require_2d_or_slices(const Array& a, const char* what) {
  const std::size_t r = a.rank();
  if ((r != 2 && r != 3) || a.shape[r - 2] < kQualitySmallestSide ||
      a.shape[r - 1] < kQualitySmallestSide || a.size() == 0)
    throw InputError(std::string(what) + " must be a 2D image or a volume of slices, " +
                     smallest_sides());
}

double disc_radius(const Array& a) {
  return 0.5 * static_cast<double>(std::min(a.shape[0], a.shape[1])) - 1.0;
}

double radius_of(const Array& a, std::size_t i, std::size_t k) {
  return std::hypot(static_cast<double>(i) - 0.5 * (a.shape[0] - 1.0),
                    static_cast<double>(k) - 0.5 * (a.shape[1] - 1.0));
}

// |pixel - median of its 3 x 3 neighbourhood| at every interior pixel of the disc, or -1. With
// extrema_only, 0 where the pixel lies between the neighbourhood's least and largest values:
// on an edge's slope, whose position wavers by a fraction of a pixel, the median jumps between
// the two sides although no pixel stands out (docs/history/RESULTS.md, issue 29: 56 of the
// 87 pixels of riner's wood image over 6 sigmas by the plain residual lie on such slopes).
std::vector<double> residuals_from_median(const Array& a, bool extrema_only) {
  const std::size_t ny = a.shape[0], nx = a.shape[1];
  const double r_max = disc_radius(a);
  std::vector<double> out(a.size(), -1.0);
  std::array<float, 9> w{};
  for (std::size_t i = 1; i + 1 < ny; ++i) {
    for (std::size_t k = 1; k + 1 < nx; ++k) {
      if (radius_of(a, i, k) > r_max) continue;
      int n = 0;
      for (int di = -1; di <= 1; ++di)
        for (int dk = -1; dk <= 1; ++dk) w[n++] = a(i + di, k + dk);
      const float v = a(i, k);
      const auto [least, largest] = std::minmax_element(w.begin(), w.end());
      const bool extremum = v <= *least || v >= *largest;
      std::nth_element(w.begin(), w.begin() + 4, w.end());
      if (!std::isfinite(v) || !std::isfinite(w[4])) continue;
      out[i * nx + k] = extrema_only && !extremum ? 0.0 : std::fabs(v - w[4]);
    }
  }
  return out;
}

std::vector<double> median_residuals(const Array& a) { return residuals_from_median(a, false); }

// What a speck is: a pixel above or below all its neighbours, by its residual from their median.
std::vector<double> speck_residuals(const Array& a) { return residuals_from_median(a, true); }

// per_image of a 2D image, or of every axial slice of a volume, one after the other.
template <typename PerImage>
std::vector<double> over_slices(const Array& a, PerImage per_image) {
  if (a.rank() == 2) return per_image(a);
  std::vector<double> out;
  out.reserve(a.size());
  for (std::size_t z = 0; z < a.shape[0]; ++z) {
    const std::vector<double> r = per_image(axial_slice(a, z));
    out.insert(out.end(), r.begin(), r.end());
  }
  return out;
}

// The gradient magnitude at every interior pixel of the disc, after a Gaussian of smoothing_px.
std::vector<double> gradients(const Array& image, double smoothing_px) {
  const std::vector<double> g = metrics::gradient_magnitude(image, smoothing_px);
  std::vector<double> out;
  const double r_max = disc_radius(image);
  for (std::size_t i = 0; i < image.shape[0]; ++i) {
    for (std::size_t k = 0; k < image.shape[1]; ++k) {
      const double v = g[i * image.shape[1] + k];
      if (radius_of(image, i, k) <= r_max && std::isfinite(v)) out.push_back(v);
    }
  }
  return out;
}

// ... of each axial slice of a volume, together.
std::vector<double> disc_gradients(const Array& image, double smoothing_px) {
  return over_slices(image, [&](const Array& a) { return gradients(a, smoothing_px); });
}

// The q-quantile of v (reordered).
double quantile(std::vector<double>& v, double q) {
  const auto at = static_cast<long>(q * static_cast<double>(v.size() - 1));
  std::nth_element(v.begin(), v.begin() + at, v.end());
  return v[static_cast<std::size_t>(at)];
}

// The 8-connected regions of the pixels where `lost` (rows x columns) equals 1.
std::vector<std::vector<std::size_t>> lost_regions(const std::vector<double>& lost,
                                                   std::size_t rows, std::size_t columns) {
  std::vector<std::vector<std::size_t>> regions;
  std::vector<std::uint8_t> seen(lost.size(), 0);
  std::vector<std::size_t> pending;
  for (std::size_t start = 0; start < lost.size(); ++start) {
    if (lost[start] != 1.0 || seen[start]) continue;
    std::vector<std::size_t>& region = regions.emplace_back();
    pending.assign(1, start);
    seen[start] = 1;
    while (!pending.empty()) {
      const std::size_t p = pending.back();
      pending.pop_back();
      region.push_back(p);
      const long i = static_cast<long>(p / columns), k = static_cast<long>(p % columns);
      for (long di = -1; di <= 1; ++di) {
        for (long dk = -1; dk <= 1; ++dk) {
          const long ni = i + di, nk = k + dk;
          if (ni < 0 || nk < 0 || ni >= static_cast<long>(rows) || nk >= static_cast<long>(columns))
            continue;
          const std::size_t q =
              static_cast<std::size_t>(ni) * columns + static_cast<std::size_t>(nk);
          if (lost[q] == 1.0 && !seen[q]) {
            seen[q] = 1;
            pending.push_back(q);
          }
        }
      }
    }
  }
  return regions;
}

// The radii [low, high] of a lost region's thin arc about the grid centre, if it is one: where
// the FBP shows at least half the region's `peak` of `sigmas`, no wider radially than
// kLostArcWidthPx and kLostArcLengthToWidth times as long along the circle, kLostArcLeastRadiusPx
// or more from the centre. Such an arc is a ring of the FBP the image has not (the built-in
// demo's: four arcs 2.3-3.3 px wide, 55-123 degrees long, 0.64% of the field), or a thin
// concentric structure taken for one. At half its peak a ring of one element blurred by
// kLostBlurPx is 4.7 px wide whatever its height; the region's own extent grows with it.
std::optional<std::pair<double, double>> thin_arc_radii(
    const std::vector<std::size_t>& region, double peak, const Array& image,
    const std::function<double(std::size_t)>& sigmas) {
  const std::size_t rows = image.shape[0], columns = image.shape[1];
  double r_low = std::numeric_limits<double>::infinity(), r_high = 0.0;
  std::vector<double> angles;
  for (const std::size_t p : region) {
    if (sigmas(p) < 0.5 * peak) continue;
    const std::size_t i = p / columns, k = p % columns;
    const double r = radius_of(image, i, k);
    r_low = std::min(r_low, r);
    r_high = std::max(r_high, r);
    angles.push_back(std::atan2(static_cast<double>(i) - 0.5 * (rows - 1.0),
                                static_cast<double>(k) - 0.5 * (columns - 1.0)));
  }
  // The arc's angular span: the full turn less the widest gap between its pixels' angles.
  std::sort(angles.begin(), angles.end());
  double gap = 2.0 * M_PI - (angles.back() - angles.front());
  for (std::size_t a = 1; a < angles.size(); ++a) gap = std::max(gap, angles[a] - angles[a - 1]);
  const double width = r_high - r_low, length = (2.0 * M_PI - gap) * 0.5 * (r_low + r_high);
  if (r_low >= kLostArcLeastRadiusPx && width <= kLostArcWidthPx &&
      length >= kLostArcLengthToWidth * std::max(width, 1.0))
    return std::make_pair(r_low, r_high);
  return std::nullopt;
}

// Each 8-connected region of lost pixels (1 in `lost`, the image's shape): cleared where it is
// neither wide nor high (fewer than kLostWideRegionPixels and nowhere `sigmas`(p) above
// kLostHighSigmas), set to 2 where it is a thin arc about the centre (thin_arc_radii): said apart
// from the lost object. Only the arc's band of radii (its blur's tails included) is the arc: what
// else the region holds (a faint corner cut off the sample where a bright ring crosses it) is
// judged again on its own.
void classify_regions(std::vector<double>& lost, const Array& image,
                      const std::function<double(std::size_t)>& sigmas) {
  constexpr double kLost = 3.0;  // decided lost, while other regions are still to be judged
  for (;;) {
    const std::vector<std::vector<std::size_t>> regions =
        lost_regions(lost, image.shape[0], image.shape[1]);
    if (regions.empty()) break;
    for (const std::vector<std::size_t>& region : regions) {
      double highest = 0.0;
      for (const std::size_t p : region) highest = std::max(highest, sigmas(p));
      if (region.size() < kLostWideRegionPixels && highest < kLostHighSigmas) {
        for (const std::size_t p : region) lost[p] = 0.0;
        continue;
      }
      const auto arc = thin_arc_radii(region, highest, image, sigmas);
      if (!arc) {
        for (const std::size_t p : region) lost[p] = kLost;
        continue;
      }
      const double low = arc->first - 0.5 * kLostArcWidthPx,
                   high = arc->second + 0.5 * kLostArcWidthPx;
      for (const std::size_t p : region) {
        const double r = radius_of(image, p / image.shape[1], p % image.shape[1]);
        if (r >= low && r <= high) lost[p] = 2.0;  // the rest left at 1: judged again alone
      }
    }
  }
  for (double& v : lost) v = v == kLost ? 1.0 : v;
}

// Where the FBP sees object and the image air, per pixel of one 2D image (-1 outside the disc,
// 1 lost, 2 lost in a thin arc about the centre (thin_arc_radii), 0 not); the noise it measured
// into `noise`.
std::vector<double> lost_pixels(const Array& image, const Array& fbp, double field_radius_px,
                                double* noise) {
  const Array shown = Array(image.shape, util::gaussian_blur(image.data, image.shape, kLostBlurPx));
  const Array seen = Array(fbp.shape, util::gaussian_blur(fbp.data, fbp.shape, kLostBlurPx));
  const double r_max = std::min(disc_radius(image), field_radius_px - kFieldRimPx);
  std::vector<std::size_t> disc;
  std::vector<double> values;
  for (std::size_t i = 0; i < image.shape[0]; ++i) {
    for (std::size_t k = 0; k < image.shape[1]; ++k) {
      if (radius_of(image, i, k) > r_max) continue;
      const std::size_t p = i * image.shape[1] + k;
      if (!std::isfinite(shown.data[p]) || !std::isfinite(seen.data[p])) continue;
      disc.push_back(p);
      values.push_back(shown.data[p]);
    }
  }
  std::vector<double> out(image.size(), -1.0);
  if (disc.empty()) return out;
  const double high = util::quantile(values, 0.995);
  std::vector<double> air_shown, air_seen;
  for (std::size_t p : disc) {
    out[p] = 0.0;
    if (shown.data[p] > kLostAirShareOfHigh * high) continue;
    air_shown.push_back(shown.data[p]);
    air_seen.push_back(seen.data[p]);
  }
  if (air_seen.size() < kLostMinAirPixels) return out;
  const double level_shown = util::quantile(air_shown, 0.5);
  const double level_seen = util::quantile(air_seen, 0.5);
  for (double& v : air_seen) v = std::fabs(v - level_seen);
  const double sigma = util::kMadToSigma * util::quantile(air_seen, 0.5);
  *noise = sigma;
  for (std::size_t p : disc) {
    const double object = seen.data[p] - level_seen;
    out[p] = object > kLostObjectSigmas * sigma &&
             shown.data[p] - level_shown < kLostShownShare * object;
  }
  classify_regions(out, image, [&](std::size_t p) {
    return (seen.data[p] - level_seen) / std::max(sigma, 1e-30);
  });
  return out;
}

}  // namespace

LostObject lost_object(const Array& image, const Array& fbp, double field_radius_px) {
  require_2d_or_slices(image, "the image");
  require_2d_or_slices(fbp, "the FBP");
  if (image.shape != fbp.shape) throw InputError("the image and the FBP differ in shape");
  LostObject lost;
  double noise_sum = 0.0;
  std::size_t images = 0, disc = 0;
  auto per_image = [&](const Array& a, const Array& f) {
    double noise = 0.0;
    for (double v : lost_pixels(a, f, field_radius_px, &noise)) {
      if (v < 0.0) continue;
      ++disc;
      lost.pixels += v == 1.0;
      lost.arc_pixels += v == 2.0;
    }
    noise_sum += noise;
    ++images;
  };
  if (image.rank() == 2) {
    per_image(image, fbp);
  } else {
    for (std::size_t z = 0; z < image.shape[0]; ++z)
      per_image(axial_slice(image, z), axial_slice(fbp, z));
  }
  lost.share = disc > 0 ? static_cast<double>(lost.pixels) / static_cast<double>(disc) : 0.0;
  lost.arc_share =
      disc > 0 ? static_cast<double>(lost.arc_pixels) / static_cast<double>(disc) : 0.0;
  lost.fbp_noise = images > 0 ? noise_sum / static_cast<double>(images) : 0.0;
  return lost;
}

double edge_strength(const Array& image, double smoothing_px) {
  require_2d_or_slices(image, "the image");
  std::vector<double> g = disc_gradients(image, smoothing_px);
  if (g.empty()) return 0.0;
  return quantile(g, kEdgePercentile);
}

namespace {

struct FbpEdges {
  double scale_px = 1.0;
  double strength = 0.0;  // edge_strength(fbp, scale_px)
};

// edge_scale_px's search, keeping the FBP's edge strength at the scale it chose.
FbpEdges fbp_edges(const Array& fbp) {
  require_2d_or_slices(fbp, "the FBP");
  FbpEdges e;
  for (double scale : kEdgeScalesPx) {
    std::vector<double> g = disc_gradients(fbp, scale);
    if (g.empty()) return {kEdgeScalesPx.front(), 0.0};
    const double median = quantile(g, 0.5);
    e = {scale, quantile(g, kEdgePercentile)};
    if (e.strength >= kEdgesOverNoise * median) break;
  }
  return e;
}

}  // namespace

double edge_scale_px(const Array& fbp) { return fbp_edges(fbp).scale_px; }

double residual_noise(const Array& image) {
  require_2d_or_slices(image, "the image");
  std::vector<double> r;
  for (double v : over_slices(image, median_residuals)) {
    if (v >= 0.0) r.push_back(v);
  }
  if (r.empty()) return 0.0;
  std::nth_element(r.begin(), r.begin() + static_cast<long>(r.size() / 2), r.end());
  return util::kMadToSigma * r[r.size() / 2];
}

double specks_per_10k(const Array& image, double noise) {
  require_2d_or_slices(image, "the image");
  std::size_t specks = 0, pixels = 0;
  for (double v : over_slices(image, speck_residuals)) {
    if (v < 0.0) continue;
    ++pixels;
    specks += v > kSpeckSigmas * noise;
  }
  return pixels > 0 ? 1e4 * static_cast<double>(specks) / static_cast<double>(pixels) : 0.0;
}

CentreDeviation centre_deviation(const Array& image, const Array& fbp, int radius_px,
                                 double smoothing_px) {
  require_2d(image, "the image");
  require_2d(fbp, "the FBP");
  if (image.shape != fbp.shape) throw InputError("the image and the FBP differ in shape");
  const auto reach = static_cast<std::size_t>(std::ceil(rings::kGaussianReach * smoothing_px));
  const std::size_t bins = static_cast<std::size_t>(radius_px) + reach + 1;
  std::vector<double> pi, pf, count, unused;
  metrics::radial_means(image, bins, pi, unused);
  metrics::radial_means(fbp, bins, pf, count);
  // Gaussian over radius, over the bins that hold pixels.
  std::vector<char> filled(bins);
  for (std::size_t b = 0; b < bins; ++b) filled[b] = count[b] > 0;
  const std::vector<double> image_broad =
      rings::gaussian_smooth(pi, smoothing_px, rings::Ends::kCut, &filled);
  const std::vector<double> fbp_broad =
      rings::gaussian_smooth(pf, smoothing_px, rings::Ends::kCut, &filled);
  CentreDeviation c;
  c.radius_px = radius_px;
  double noise2 = 0.0;
  int used = 0;
  for (long r = 0; r <= radius_px; ++r) {
    if (count[static_cast<std::size_t>(r)] == 0) continue;
    const auto b = static_cast<std::size_t>(r);
    const double d = std::fabs(image_broad[b] - fbp_broad[b]);
    noise2 += (pf[b] - fbp_broad[b]) * (pf[b] - fbp_broad[b]);
    ++used;
    if (d > c.deviation) {
      c.deviation = d;
      c.at_px = static_cast<double>(r);
    }
  }
  c.fbp_noise = used > 0 ? std::sqrt(noise2 / used) : 0.0;
  c.sigmas = c.fbp_noise > 0.0 ? c.deviation / c.fbp_noise : 0.0;
  return c;
}

double field_radius_px(const Geometry& g) { return field_of_view(g).radius_mm / g.voxel_mm; }

QualityReport quality_against_fbp(const Array& image, const Array& fbp, double field_radius_px) {
  require_2d_or_slices(image, "the image");
  require_2d_or_slices(fbp, "the FBP");
  if (image.shape != fbp.shape) throw InputError("the image and the FBP differ in shape");
  QualityReport q;
  q.noise = residual_noise(fbp);
  q.ring_index = ring_index(image);
  q.fbp_ring_index = ring_index(fbp);
  q.specks_per_10k = specks_per_10k(image, q.noise);
  q.fbp_specks_per_10k = specks_per_10k(fbp, q.noise);
  const FbpEdges edges = fbp_edges(fbp);
  q.edge_scale_px = edges.scale_px;
  q.edge_strength = edge_strength(image, edges.scale_px);
  q.fbp_edge_strength = edges.strength;
  q.lost = lost_object(image, fbp, field_radius_px);
  if (image.rank() == 2) q.centre = centre_deviation(image, fbp);
  return q;
}

}  // namespace riner
