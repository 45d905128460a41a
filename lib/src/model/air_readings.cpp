#include "model/air_readings.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "preprocessing/stripes.hpp"
#include "util/parallel.hpp"
#include "util/robust_statistics.hpp"

namespace riner::model {

namespace {

// Spread of an element's readings: the interquartile range of a normal is 1.349 sigma.
constexpr double kIqrPerSigma = 1.349;
// An element reads air in every view when its spread is close to the quietest elements' and
// nothing sticks out (the range of 360 normal samples is about 6 sigma) but a hiccup or two.
constexpr double kAirSpreadFactor = 2.0;
constexpr double kAirRangeSigmas = 12.0;
constexpr std::size_t kRangeTrim = 2;
// An air reading is -ln alpha: a detector whose responses are within [0.6, 1.65] of the flat
// field. Steadier, larger readings are an object centred on the axis that every view shows
// alike (wider than the detector, say), not air.
constexpr double kMaxAirOffset = 0.5;
// Normalised by a flat field, air reads about 0 on average (-ln of responses around 1; the
// shared scans: -0.001 to 0.04). Steady readings that average more are an object centred on
// the axis, or a scan normalised by the wrong I0: no carving.
constexpr double kMaxAirLevel = 0.1;
// Fewer air elements than this: no trustworthy noise or offset range, so no carving.
constexpr std::size_t kMinAirElements = 4;
// Noise floor (rho units) for noise-free simulations.
constexpr double kNoiseFloor = 1e-5;
// Outlier views: air noisier than this many times the median view's, or a level this many
// sigma off the running median of its neighbours' (a slow drift of the source is no outlier).
// The shared real scans: at most 1.55 times, and levels within 1.1 sigma of 0.
constexpr double kOutlierNoiseFactor = 2.0;
constexpr double kOutlierLevelSigmas = 3.0;
constexpr std::size_t kLevelNeighbours = 5;
// More outlier views than this share: the air elements are not air after all; no carving.
constexpr double kMostOutlierShare = 0.1;
// An element's air cluster: its readings within this many sigma of its lowest but
// kSpikesBelow, at least kMinAirReadings of them.
constexpr double kClusterSigmas = 4.0;
constexpr std::size_t kSpikesBelow = 2;
constexpr std::size_t kMinAirReadings = 3;
// Stripe offsets: the running median's half width along the row (wide, so that the median of
// the neighbours' responses is steady), and how far above them an offset from the readings may
// lie: 4 sigma of the stripe offsets' error, and at least 2 noise sigma.
constexpr std::size_t kStripeReach = 25;
constexpr double kStripeQuantile = 0.25;
constexpr double kStripeToleranceSigmas = 4.0;
constexpr double kStripeToleranceNoise = 2.0;

struct ElementStats {
  std::size_t finite = 0;
  double median = 0.0;
  double sigma = 0.0;
  double range = 0.0;  // without the kRangeTrim highest and lowest readings
};

double median_of(std::vector<double>& v) { return util::quantile(v, 0.5); }

std::vector<ElementStats> element_stats(const Scan& scan, std::size_t per_view) {
  const std::size_t views = scan.geometry.n_views();
  std::vector<ElementStats> stats(per_view);
  util::parallel_for(per_view, [&](std::size_t begin, std::size_t end) {
    std::vector<double> r;
    for (std::size_t e = begin; e < end; ++e) {
      r.clear();
      for (std::size_t v = 0; v < views; ++v) {
        const float x = scan.measurement.data[v * per_view + e];
        if (std::isfinite(x)) r.push_back(x);
      }
      ElementStats& s = stats[e];
      s.finite = r.size();
      if (r.empty()) continue;
      std::sort(r.begin(), r.end());
      auto q = [&](double f) { return r[static_cast<std::size_t>(f * (r.size() - 1))]; };
      s.median = q(0.5);
      s.sigma = (q(0.75) - q(0.25)) / kIqrPerSigma;
      const std::size_t trim = r.size() >= 10 * kRangeTrim ? kRangeTrim : 0;
      s.range = r[r.size() - 1 - trim] - r[trim];
    }
  });
  return stats;
}

// The elements that read air in every view.
std::vector<std::size_t> air_elements(const std::vector<ElementStats>& stats, std::size_t views) {
  std::vector<double> spreads;
  for (const ElementStats& s : stats) {
    if (s.finite == views) spreads.push_back(s.sigma);
  }
  if (spreads.empty()) return {};
  const double quiet = std::max(util::quantile(spreads, 0.1), kNoiseFloor);
  std::vector<std::size_t> air;
  for (std::size_t e = 0; e < stats.size(); ++e) {
    const ElementStats& s = stats[e];
    if (s.finite != views || s.sigma > kAirSpreadFactor * quiet ||
        s.range > kAirRangeSigmas * std::max(s.sigma, kNoiseFloor) ||
        std::fabs(s.median) > kMaxAirOffset)
      continue;
    air.push_back(e);
  }
  return air;
}

// Each view's level and noise over the air elements, the noise of a mean of three neighbours
// (over the air elements whose neighbours are air too: a detector's noise is often correlated
// between neighbours, a scintillator's light spreading), and which views are outliers.
void read_views(const Scan& scan, const std::vector<ElementStats>& stats,
                const std::vector<std::size_t>& air, AirReadings& a) {
  const std::size_t views = scan.geometry.n_views(), n_u = scan.geometry.n_u;
  std::vector<std::uint8_t> is_air(a.per_view, 0);
  for (std::size_t e : air) is_air[e] = 1;
  std::vector<std::size_t> triples;  // air elements with air on both sides in their row
  for (std::size_t e : air) {
    const std::size_t column = e % n_u;
    if (column > 0 && column + 1 < n_u && is_air[e - 1] && is_air[e + 1]) triples.push_back(e);
  }
  a.view_level.assign(views, 0.0);
  a.view_noise.assign(views, kNoiseFloor);
  a.view_noise3.assign(views, kNoiseFloor);
  util::parallel_for(views, [&](std::size_t begin, std::size_t end) {
    std::vector<double> d, d3;
    for (std::size_t v = begin; v < end; ++v) {
      const float* line = scan.measurement.ptr() + v * a.per_view;
      d.clear();
      for (std::size_t e : air) d.push_back(line[e] - stats[e].median);
      const double level = median_of(d);
      for (double& x : d) x = std::fabs(x - level);
      a.view_level[v] = level;
      a.view_noise[v] = std::max(util::kMadToSigma * median_of(d), kNoiseFloor);
      d3.clear();
      for (std::size_t e : triples) {
        double sum = 0.0;
        for (std::size_t k = e - 1; k <= e + 1; ++k) sum += line[k] - stats[k].median;
        d3.push_back(std::fabs(sum / 3.0 - level));
      }
      // Without triples (air elements scattered), as if the noise were independent.
      a.view_noise3[v] = d3.empty() ? a.view_noise[v] / std::sqrt(3.0)
                                    : std::max(util::kMadToSigma * median_of(d3), kNoiseFloor);
    }
  });
  std::vector<double> noises = a.view_noise;
  a.noise = median_of(noises);
  a.outlier_view.assign(views, 0);
  std::vector<double> near;
  for (std::size_t v = 0; v < views; ++v) {
    near.clear();
    const std::size_t lo = v >= kLevelNeighbours ? v - kLevelNeighbours : 0;
    for (std::size_t k = lo; k < std::min(views, v + kLevelNeighbours + 1); ++k) {
      if (k != v) near.push_back(a.view_level[k]);
    }
    const double drift = near.empty() ? 0.0 : median_of(near);
    a.outlier_view[v] = a.view_noise[v] > kOutlierNoiseFactor * a.noise ||
                        std::fabs(a.view_level[v] - drift) > kOutlierLevelSigmas * a.noise;
    a.outlier_views += a.outlier_view[v];
  }
}

// Each element's offset as its row's stripes tell it: the air's level plus the element's mean
// over the views less the low quantile of its neighbours' means, plus `rise` (how far the air
// elements' median lies above that quantile of theirs). Blind to a detector whose responses
// drift smoothly along the row, but never to the object: the mean of a projection over the
// views is smooth across elements.
std::vector<double> stripe_offsets(const Scan& scan, const AirReadings& a, double rise) {
  const std::size_t views = scan.geometry.n_views(), n_u = scan.geometry.n_u;
  std::vector<double> mean(a.per_view, 0.0), count(a.per_view, 0.0);
  for (std::size_t v = 0; v < views; ++v) {
    if (a.outlier_view[v]) continue;
    for (std::size_t e = 0; e < a.per_view; ++e) {
      const float x = scan.measurement.data[v * a.per_view + e];
      if (!std::isfinite(x)) continue;
      mean[e] += x - a.view_level[v];
      count[e] += 1.0;
    }
  }
  for (std::size_t e = 0; e < a.per_view; ++e) mean[e] = count[e] > 0.0 ? mean[e] / count[e] : NAN;
  const std::vector<double> low =
      preprocessing::row_quantile(mean, n_u, kStripeReach, kStripeQuantile);
  std::vector<double> out(a.per_view, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t e = 0; e < a.per_view; ++e) {
    if (std::isfinite(mean[e])) out[e] = a.air_offset_median + mean[e] - (low[e] + rise);
  }
  return out;
}

// Per element, the median of the low cluster of its level-corrected readings (NaN: too few).
std::vector<double> cluster_offsets(const Scan& scan, const AirReadings& a) {
  const std::size_t views = scan.geometry.n_views();
  std::vector<double> out(a.per_view, std::numeric_limits<double>::quiet_NaN());
  util::parallel_for(a.per_view, [&](std::size_t begin, std::size_t end) {
    std::vector<double> r;
    for (std::size_t e = begin; e < end; ++e) {
      r.clear();
      for (std::size_t v = 0; v < views; ++v) {
        const float x = scan.measurement.data[v * a.per_view + e];
        if (!a.outlier_view[v] && std::isfinite(x)) r.push_back(x - a.view_level[v]);
      }
      if (r.size() < kMinAirReadings) continue;
      std::sort(r.begin(), r.end());
      // Anchored above the lowest readings: a real detector's negative spikes sit far below the
      // air, and a window from the lowest held nothing else (wood_neutron: a third of its
      // elements).
      const double anchor = r[std::min(kSpikesBelow, r.size() - 1)];
      const auto cluster = static_cast<std::size_t>(
          std::upper_bound(r.begin(), r.end(), anchor + kClusterSigmas * a.noise) - r.begin());
      if (cluster >= kMinAirReadings) out[e] = r[(cluster - 1) / 2];
    }
  });
  return out;
}

// The offsets: from the readings' low cluster, where that lies in the band the air elements
// span and no higher than the stripes allow. An element whose lowest readings are object (it
// never sees past it: the middle of a wide, faint sample) reads above its stripe offset by the
// object's thinnest projection; without the second test it would certify that projection as air.
void read_offsets(const Scan& scan, const std::vector<ElementStats>& stats,
                  const std::vector<std::size_t>& air, double noise_sigmas, AirReadings& a) {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (std::size_t e : air) {
    lo = std::min(lo, stats[e].median);
    hi = std::max(hi, stats[e].median);
  }
  const double widen = 0.25 * (hi - lo) + noise_sigmas * a.noise;
  lo -= widen;
  hi += widen;
  const std::vector<double> cluster = cluster_offsets(scan, a);
  std::vector<double> responses;
  for (std::size_t e : air) responses.push_back(stats[e].median);
  const double rise = util::quantile(responses, 0.5) - util::quantile(responses, kStripeQuantile);
  const std::vector<double> stripe = stripe_offsets(scan, a, rise);
  // How well the stripes tell an offset: as well as a quartile of 2R + 1 responses spread like
  // the air elements' (a normal's: 1.36 sigma / sqrt(n)), and no better than they agree with the
  // air elements' own clusters (whose neighbours are all air, so this alone is too kind: 6e-4
  // on the paper's protocol, where the responses spread by 0.15).
  std::vector<double> gaps;
  for (std::size_t e : air) {
    if (std::isfinite(cluster[e]) && std::isfinite(stripe[e]))
      gaps.push_back(cluster[e] - stripe[e]);
  }
  const double centre = gaps.empty() ? 0.0 : util::quantile(gaps, 0.5);
  for (double& d : gaps) d = std::fabs(d - centre);
  const double spread = gaps.empty() ? 0.0 : util::kMadToSigma * util::quantile(gaps, 0.5);
  const double response_level = util::quantile(responses, 0.5);
  for (double& r : responses) r = std::fabs(r - response_level);
  const double median_error = 1.36 * util::kMadToSigma * util::quantile(responses, 0.5) /
                              std::sqrt(2.0 * kStripeReach + 1.0);
  a.stripe_tolerance =
      centre + std::max({kStripeToleranceSigmas * spread, kStripeToleranceSigmas * median_error,
                         kStripeToleranceNoise * a.noise});
  a.offset.assign(a.per_view, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t e = 0; e < a.per_view; ++e) {
    const double c = cluster[e];
    if (!(c >= lo && c <= hi)) continue;
    if (std::isfinite(stripe[e]) && c - stripe[e] > a.stripe_tolerance) {
      ++a.above_stripes;
      continue;
    }
    a.offset[e] = c;
  }
}

}  // namespace

double AirReadings::mean_excess(const Scan& scan, std::size_t view, std::size_t element,
                                int& used) const {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  used = 0;
  if (!usable || outlier_view[view] || !std::isfinite(offset[element])) return kNaN;
  const std::size_t n_u = scan.geometry.n_u;
  const std::size_t column = element % n_u;
  const float* line = scan.measurement.ptr() + view * per_view;
  double sum = 0.0;
  for (std::size_t c = column > 0 ? column - 1 : 0; c <= std::min(column + 1, n_u - 1); ++c) {
    const std::size_t e = element - column + c;
    const float x = line[e];
    if (!std::isfinite(x) || !std::isfinite(offset[e])) {
      if (e == element) return kNaN;
      continue;
    }
    sum += x - view_level[view] - offset[e];
    ++used;
  }
  return sum / used;
}

double AirReadings::excess(const Scan& scan, std::size_t view, std::size_t element) const {
  int used = 0;
  return mean_excess(scan, view, element, used);
}

double AirReadings::excess_sigmas(const Scan& scan, std::size_t view, std::size_t element) const {
  int used = 0;
  const double mean = mean_excess(scan, view, element, used);
  if (used == 0) return mean;  // NaN (view_noise3 is empty when nothing is usable)
  // Fewer than three (the row's ends, a dead neighbour): as if the noise were independent.
  return mean / (view_noise3[view] * std::sqrt(3.0 / used));
}

std::vector<std::uint8_t> AirReadings::certified(const Scan& scan, double sigmas) const {
  const std::size_t views = scan.geometry.n_views();
  std::vector<std::uint8_t> out(views * per_view, 0);
  if (!usable) return out;
  util::parallel_for(views, [&](std::size_t begin, std::size_t end) {
    for (std::size_t v = begin; v < end; ++v) {
      for (std::size_t e = 0; e < per_view; ++e) {
        out[v * per_view + e] = excess_sigmas(scan, v, e) < sigmas;  // false for NaN
      }
    }
  });
  return out;
}

AirReadings read_air(const Scan& scan, double noise_sigmas) {
  const Geometry& g = scan.geometry;
  AirReadings a;
  a.per_view = g.n_u * (g.is_3d() ? g.n_v : 1);
  const std::vector<ElementStats> stats = element_stats(scan, a.per_view);
  bool any_full = false;
  for (const ElementStats& s : stats) any_full = any_full || s.finite == g.n_views();
  if (!any_full) {
    a.note = "no detector element has a finite reading in every view";
    return a;
  }
  const std::vector<std::size_t> air = air_elements(stats, g.n_views());
  a.air_elements = air.size();
  if (air.size() < std::max(kMinAirElements, a.per_view / 100)) {
    a.note =
        "too few detector elements read air in every view (" + std::to_string(air.size()) + ")";
    return a;
  }
  std::vector<double> medians;
  for (std::size_t e : air) medians.push_back(stats[e].median);
  a.air_offset_median = median_of(medians);
  if (std::fabs(a.air_offset_median) > kMaxAirLevel) {
    a.note = "the steadiest readings average " + std::to_string(a.air_offset_median) +
             ", not the 0 of air in a flat-field-normalised scan";
    return a;
  }
  read_views(scan, stats, air, a);
  if (static_cast<double>(a.outlier_views) > kMostOutlierShare * static_cast<double>(g.n_views())) {
    a.note = std::to_string(a.outlier_views) + " of " + std::to_string(g.n_views()) +
             " views read their air off the others' level or noise";
    return a;
  }
  read_offsets(scan, stats, air, noise_sigmas, a);
  a.usable = true;
  return a;
}

}  // namespace riner::model
