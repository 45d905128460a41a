#include "riner/angular_range.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "preprocessing/angular_range_reading.hpp"
#include "preprocessing/centre_readings.hpp"
#include "preprocessing/mismatch_sums.hpp"
#include "riner/centre.hpp"

namespace riner {

namespace {

// Wide detectors are binned to about this many columns: the comparisons need the object's
// shape, not its finest detail, and stay a few tens of milliseconds.
constexpr std::size_t kMostColumns = 512;
constexpr std::size_t kMostPairs = 16;
constexpr std::size_t kMostRows = 4;
// One comparison must beat the other by this factor to count.
constexpr double kClearly = 4.0;
// The running median of the elements' means that a stripe stands out from.
constexpr std::size_t kStripeWindow = 9;

// The lines compared: [views][rows][binned columns], NaN where a bin holds a non-finite
// reading, each binned element's stripe taken out.
struct Lines {
  std::size_t views = 0, rows = 0, columns = 0;
  std::vector<double> data;
  const double* line(std::size_t view, std::size_t row) const {
    return data.data() + (view * rows + row) * columns;
  }
};

Lines binned_lines(const Scan& scan) {
  const Geometry& g = scan.geometry;
  const std::size_t views = g.n_views(), n_u = g.n_u, n_v = g.is_3d() ? g.n_v : 1;
  std::vector<std::size_t> rows;
  if (n_v == 1) {
    rows.push_back(0);
  } else {
    // Spread over the detector, each row a slice of its own.
    const std::size_t count = std::min(kMostRows, n_v);
    for (std::size_t i = 0; i < count; ++i) rows.push_back((n_v * (2 * i + 1)) / (2 * count));
  }
  const std::size_t bin = (n_u + kMostColumns - 1) / kMostColumns;
  Lines out;
  out.views = views;
  out.rows = rows.size();
  out.columns = n_u / bin;
  out.data.assign(views * out.rows * out.columns, 0.0);
  for (std::size_t a = 0; a < views; ++a) {
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const float* src = scan.measurement.ptr() + (a * n_v + rows[r]) * n_u;
      double* dst = out.data.data() + (a * out.rows + r) * out.columns;
      for (std::size_t k = 0; k < out.columns; ++k) {
        double sum = 0.0;
        for (std::size_t j = k * bin; j < (k + 1) * bin; ++j) sum += src[j];
        dst[k] = std::isfinite(sum) ? sum / static_cast<double>(bin)
                                    : std::numeric_limits<double>::quiet_NaN();
      }
    }
  }
  // Stripes: an element's offset is the same in a view and in itself a turn later, and cancels;
  // between mirror images two elements' offsets add, and a strongly ringed scan of a faint
  // object would read as a full turn.
  const std::size_t per_view = out.rows * out.columns;
  std::vector<double> mean(per_view, 0.0);
  std::vector<std::size_t> count(per_view, 0);
  for (std::size_t i = 0; i < out.data.size(); ++i) {
    if (std::isfinite(out.data[i])) mean[i % per_view] += out.data[i], ++count[i % per_view];
  }
  for (std::size_t e = 0; e < per_view; ++e) {
    mean[e] = count[e] ? mean[e] / static_cast<double>(count[e])
                       : std::numeric_limits<double>::quiet_NaN();
  }
  std::vector<double> stripe(per_view, 0.0);
  std::vector<double> window;
  for (std::size_t r = 0; r < out.rows; ++r) {
    const double* m = mean.data() + r * out.columns;
    for (std::size_t k = 0; k < out.columns; ++k) {
      if (!std::isfinite(m[k])) continue;
      window.clear();
      const std::size_t half = kStripeWindow / 2;
      for (std::size_t j = k >= half ? k - half : 0; j <= std::min(k + half, out.columns - 1);
           ++j) {
        if (std::isfinite(m[j])) window.push_back(m[j]);
      }
      std::nth_element(window.begin(), window.begin() + window.size() / 2, window.end());
      stripe[r * out.columns + k] = m[k] - window[window.size() / 2];
    }
  }
  for (std::size_t i = 0; i < out.data.size(); ++i) out.data[i] -= stripe[i % per_view];
  return out;
}

struct ViewPair {
  std::size_t first, second;
};

// Pairs of views `apart` radians apart within 1.01 mean angular steps (the nearest view to
// each view's angle plus `apart`), thinned evenly to kMostPairs.
std::vector<ViewPair> pairs_apart(const std::vector<double>& angles, double apart, double step) {
  std::vector<std::size_t> order(angles.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t x, std::size_t y) { return angles[x] < angles[y]; });
  std::vector<ViewPair> all;
  for (std::size_t i = 0; i < angles.size(); ++i) {
    const double target = angles[i] + apart;
    const auto above = std::lower_bound(order.begin(), order.end(), target,
                                        [&](std::size_t k, double t) { return angles[k] < t; });
    std::size_t best = angles.size();
    double best_gap = std::numeric_limits<double>::infinity();
    for (auto it = above == order.begin() ? above : above - 1; it != order.end() && it <= above;
         ++it) {
      const double gap = std::fabs(angles[*it] - target);
      if (*it != i && gap < best_gap) best_gap = gap, best = *it;
    }
    if (best < angles.size() && best_gap <= 1.01 * step) all.push_back({i, best});
  }
  std::vector<ViewPair> out;
  const std::size_t m = std::min(all.size(), kMostPairs);
  for (std::size_t i = 0; i < m; ++i) out.push_back(all[i * all.size() / m]);
  return out;
}

// The pairs' readings as they are: relative mismatch.
double same_mismatch(const Lines& l, const std::vector<ViewPair>& pairs) {
  preprocessing::MismatchSums sums;
  for (const ViewPair& p : pairs) {
    for (std::size_t r = 0; r < l.rows; ++r) {
      const double* a = l.line(p.first, r);
      const double* b = l.line(p.second, r);
      for (std::size_t k = 0; k < l.columns; ++k) {
        if (std::isfinite(a[k]) && std::isfinite(b[k])) sums.add(a[k], b[k]);
      }
    }
  }
  return sums.relative();
}

// The second of each pair mirrored about `axis` (binned columns): relative mismatch.
double mirrored_mismatch_at(const Lines& l, const std::vector<ViewPair>& pairs, double axis) {
  preprocessing::MismatchSums sums;
  const std::size_t n = l.columns;
  for (const ViewPair& p : pairs) {
    for (std::size_t r = 0; r < l.rows; ++r) {
      const double* a = l.line(p.first, r);
      const double* b = l.line(p.second, r);
      for (std::size_t k = 0; k < n; ++k) {
        const double x = 2.0 * axis - static_cast<double>(k);
        if (x < 0.0 || x > static_cast<double>(n - 1)) continue;
        const auto j = static_cast<std::size_t>(x);
        const double t = x - static_cast<double>(j);
        const double mirrored = (1.0 - t) * b[j] + t * b[std::min(j + 1, n - 1)];
        if (std::isfinite(a[k]) && std::isfinite(mirrored)) sums.add(a[k], mirrored);
      }
    }
  }
  return sums.relative();
}

// The least mirrored mismatch over the axes of the centre finders' central search.
double mirrored_mismatch(const Lines& l, const std::vector<ViewPair>& pairs) {
  const double n = static_cast<double>(l.columns);
  const double centre = 0.5 * (n - 1.0);
  double best = std::numeric_limits<double>::infinity();
  for (double a = centre - kCentreSearchShare * n; a <= centre + kCentreSearchShare * n; a += 0.5) {
    best = std::min(best, mirrored_mismatch_at(l, pairs, a));
  }
  return best;
}

// What the angles say: their span and which turn it is (kNotChecked for a divergent beam,
// fewer than 8 views or 16 columns, or a span of neither turn within 4 steps).
AngularRangeEvidence by_angles(const Geometry& g) {
  AngularRangeEvidence e;
  if (g.is_divergent() || g.n_views() < 8 || g.n_u < 16) return e;
  const auto [lo, hi] = std::minmax_element(g.angles.begin(), g.angles.end());
  const double span = *hi - *lo;
  const double step = span / static_cast<double>(g.angles.size() - 1);
  e.span_deg = span * 180.0 / M_PI;
  if (std::fabs(span - M_PI) <= 4.0 * step) {
    e.geometry = TurnReading::kHalfTurn;
  } else if (std::fabs(span - 2.0 * M_PI) <= 4.0 * step) {
    e.geometry = TurnReading::kFullTurn;
  }
  return e;
}

const char* turn_name(TurnReading t) {
  return t == TurnReading::kHalfTurn ? "a half-turn (180 degrees)" : "a full turn (360 degrees)";
}

}  // namespace

AngularRangeEvidence read_angular_range(const Scan& scan) {
  // Readings are prepared (stuck elements found over the whole scan) only where the angles
  // call for a reading: a fan beam's load paid for it and read nothing.
  const AngularRangeEvidence angles_alone = by_angles(scan.geometry);
  if (angles_alone.geometry == TurnReading::kNotChecked) return angles_alone;
  return preprocessing::read_prepared_angular_range(preprocessing::prepared(scan));
}

AngularRangeEvidence preprocessing::read_prepared_angular_range(const Scan& scan) {
  AngularRangeEvidence e = by_angles(scan.geometry);
  if (e.geometry == TurnReading::kNotChecked) return e;
  const std::vector<double>& angles = scan.geometry.angles;
  const auto [lo, hi] = std::minmax_element(angles.begin(), angles.end());
  const double step = (*hi - *lo) / static_cast<double>(angles.size() - 1);
  const double turn = e.geometry == TurnReading::kHalfTurn ? M_PI : 2.0 * M_PI;
  // The end pairs: the geometry's span apart (the last view lies a step short of it when the
  // angles leave out their endpoint).
  const std::vector<ViewPair> ends = pairs_apart(angles, turn, step);
  const std::vector<ViewPair> middles = pairs_apart(angles, 0.5 * turn, step);
  e.end_pairs = ends.size();
  e.middle_pairs = middles.size();
  e.readings = TurnReading::kUndecided;
  if (ends.empty() || middles.size() < 4) return e;
  const Lines lines = binned_lines(scan);
  e.end_same = same_mismatch(lines, ends);
  e.end_mirrored = mirrored_mismatch(lines, ends);
  e.middle_same = same_mismatch(lines, middles);
  e.middle_mirrored = mirrored_mismatch(lines, middles);
  // Under a half-turn, the ends are mirror images and the middles (a quarter-turn apart)
  // unrelated; had it turned twice as far, the ends would be the same view and the middles
  // mirror images. Under a full turn the roles swap: the middles are mirror images, the ends
  // the same view; had it turned half as far, the ends would be mirror images and the middles
  // a quarter-turn apart. Either way: ends that match as they are and middles that match
  // mirrored say a full turn, ends that match mirrored and middles that do not say a half.
  // Readings without spread compare as infinity: nothing to read.
  for (const double m : {e.end_same, e.end_mirrored, e.middle_same, e.middle_mirrored}) {
    if (!std::isfinite(m)) return e;
  }
  const bool ends_same = e.end_same * kClearly <= e.end_mirrored;
  const bool ends_mirrored = e.end_mirrored * kClearly <= e.end_same;
  const bool middles_mirrored = e.middle_mirrored * kClearly <= e.middle_same;
  // A half-turn needs its middles to match clearly worse than its ends mirrored: the absence of
  // a full turn's evidence is not enough (a full turn whose sample drifts 4 px spoils its ends
  // as they are and brings its middles' two ways close, and read as a half-turn).
  const bool middles_unrelated = e.end_mirrored * kClearly <= e.middle_mirrored;
  if (ends_same && middles_mirrored) {
    e.readings = TurnReading::kFullTurn;
  } else if (ends_mirrored && middles_unrelated && !middles_mirrored) {
    e.readings = TurnReading::kHalfTurn;
  }
  return e;
}

std::optional<std::string> angular_range_doubt(const AngularRangeEvidence& e) {
  const bool decided = e.readings == TurnReading::kHalfTurn || e.readings == TurnReading::kFullTurn;
  if (!decided || e.readings == e.geometry) return std::nullopt;
  const bool full = e.readings == TurnReading::kFullTurn;
  char line[600];
  std::snprintf(
      line, sizeof(line),
      "the views cover %s, the geometry's angles %.1f degrees: the last view matches the first "
      "%s (mismatch %.1f%% of the readings' spread; %s: %.1f%%) and views %.0f degrees apart "
      "by the geometry match %s (%.1f%%; %s: %.1f%%); check the geometry's angles (a "
      "reconstruction under the wrong range is garbage)",
      turn_name(e.readings), e.span_deg, full ? "as it is" : "mirrored",
      100.0 * (full ? e.end_same : e.end_mirrored), full ? "mirrored" : "as it is",
      100.0 * (full ? e.end_mirrored : e.end_same), full ? 90.0 : 180.0,
      full ? "mirrored" : "neither way", 100.0 * e.middle_mirrored, "as they are",
      100.0 * e.middle_same);
  return std::string(line);
}

std::optional<std::string> angular_range_doubt(const Scan& scan) {
  return angular_range_doubt(read_angular_range(scan));
}

}  // namespace riner
