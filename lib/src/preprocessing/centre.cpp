#include "riner/centre.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "preprocessing/angular_range_reading.hpp"
#include "preprocessing/centre_conjugate.hpp"
#include "preprocessing/centre_readings.hpp"
#include "preprocessing/centre_sinogram.hpp"
#include "preprocessing/fan_doubts.hpp"
#include "preprocessing/mismatch_sums.hpp"
#include "riner/angular_range.hpp"
#include "riner/array.hpp"
#include "riner/error.hpp"
#include "riner/rays.hpp"

namespace riner {

namespace {

[[noreturn]] void throw_without_structure() {
  throw InputError(
      "the readings are all equal: they hold nothing to find the centre from; pass the offset "
      "with --offset-px");
}

// Enough pairs and rows for a stable sum, few enough to stay a fraction of a second.
constexpr std::size_t kMostPairs = 32;
constexpr double kCoarseStepPx = 0.5;
constexpr double kFineStepPx = 0.02;

// View `first` and the view half a turn later: exactly one view, or two views either side of
// it, interpolated in angle (a 360-degree scan with an odd number of views).
struct ViewPair {
  std::size_t first;
  std::size_t before;
  std::size_t after;
  double weight;  // of `after`
};

std::vector<ViewPair> opposite_views(const std::vector<double>& angles) {
  const std::size_t n = angles.size();
  double span = 0.0;
  for (std::size_t i = 1; i < n; ++i) span += std::fabs(angles[i] - angles[i - 1]);
  const double step = n > 1 ? span / static_cast<double>(n - 1) : 0.0;
  std::vector<ViewPair> pairs;
  for (std::size_t i = 0; i < n; ++i) {
    // The nearest views at or before and at or after angle i + pi, modulo a full turn.
    double below = -std::numeric_limits<double>::infinity();
    double above = std::numeric_limits<double>::infinity();
    std::size_t before = n, after = n;
    for (std::size_t k = 0; k < n; ++k) {
      if (k == i) continue;
      const double d = std::remainder(angles[k] - angles[i] - M_PI, 2.0 * M_PI);
      if (d <= 0.0 && d > below) {
        below = d;
        before = k;
      }
      if (d >= 0.0 && d < above) {
        above = d;
        after = k;
      }
    }
    // An exact pair once (from its earlier view), not again from the other end.
    if (before < n && -below <= 0.25 * step) {
      if (i < before) pairs.push_back({i, before, before, 0.0});
    } else if (after < n && above <= 0.25 * step) {
      if (i < after) pairs.push_back({i, after, after, 0.0});
    } else if (before < n && after < n && above - below <= 1.5 * step) {
      pairs.push_back({i, before, after, -below / (above - below)});
    }
  }
  return pairs;
}

// Indices 0..n-1 thinned to at most `most`, evenly.
std::vector<std::size_t> evenly(std::size_t n, std::size_t most) {
  std::vector<std::size_t> out;
  const std::size_t m = std::min(n, most);
  for (std::size_t i = 0; i < m; ++i) out.push_back(i * n / m);
  return out;
}

// One detector line of view v, row r.
const float* line_of(const Scan& s, std::size_t view, std::size_t row) {
  const Geometry& g = s.geometry;
  const std::size_t rows = g.is_3d() ? g.n_v : 1;
  return s.measurement.ptr() + (view * rows + row) * g.n_u;
}

// A pair's two lines in one row: the first view's, and half a turn later's.
struct LinePair {
  const float* first;
  std::vector<float> opposite;
};

std::vector<LinePair> line_pairs(const Scan& s, const std::vector<ViewPair>& pairs,
                                 const std::vector<std::size_t>& rows) {
  std::vector<LinePair> out;
  const std::size_t n = s.geometry.n_u;
  for (const ViewPair& p : pairs) {
    for (std::size_t r : rows) {
      const float* a = line_of(s, p.before, r);
      const float* b = line_of(s, p.after, r);
      LinePair lp{line_of(s, p.first, r), std::vector<float>(n)};
      for (std::size_t j = 0; j < n; ++j) {
        lp.opposite[j] = static_cast<float>((1.0 - p.weight) * a[j] + p.weight * b[j]);
      }
      out.push_back(std::move(lp));
    }
  }
  return out;
}

// Every column j where line a and line b mirrored about column `axis` both see: visit(a[j],
// b[2 axis - j] linearly interpolated), finite readings only.
template <typename Visit>
void for_each_mirrored(const float* a, const float* b, std::size_t n, double axis, Visit visit) {
  for (std::size_t j = 0; j < n; ++j) {
    const double x = 2.0 * axis - static_cast<double>(j);
    if (x < 0.0 || x > static_cast<double>(n - 1)) continue;
    const auto k = static_cast<std::size_t>(x);
    const double t = x - static_cast<double>(k);
    const float va = a[j];
    const float b0 = b[k];
    const float b1 = b[std::min(k + 1, n - 1)];
    if (!std::isfinite(va) || !std::isfinite(b0) || !std::isfinite(b1)) continue;
    visit(va, (1.0 - t) * b0 + t * b1);
  }
}

// The mismatch sums of a candidate axis over the given line pairs.
preprocessing::MismatchSums mismatch_at(std::span<const LinePair> lines, std::size_t n,
                                        double axis) {
  preprocessing::MismatchSums sums;
  for (const LinePair& p : lines) {
    for_each_mirrored(p.first, p.opposite.data(), n, axis,
                      [&](double a, double b) { sums.add(a, b); });
  }
  return sums;
}

// The cost of a candidate axis: the mean squared difference of the mirrored pairs.
double cost_at(std::span<const LinePair> lines, std::size_t n, double axis) {
  return mismatch_at(lines, n, axis).mean();
}

// The best axis: a coarse scan over the central half of the detector (the pair must overlap
// by at least half its width), then a fine one around the coarse minimum. `width`: how far the
// cost takes to rise 10% above its minimum (a shallow minimum is unsure).
double best_axis(std::span<const LinePair> lines, std::size_t n_u, double* width = nullptr) {
  auto cost = [&](double a) { return cost_at(lines, n_u, a); };
  const double n = static_cast<double>(n_u);
  const double centre = 0.5 * (n - 1.0);
  double best = centre, best_cost = std::numeric_limits<double>::infinity();
  auto consider = [&](double a) {
    const double c = cost(a);
    if (c < best_cost) {
      best_cost = c;
      best = a;
    }
  };
  for (double a = centre - kCentreSearchShare * n; a <= centre + kCentreSearchShare * n;
       a += kCoarseStepPx) {
    consider(a);
  }
  const double coarse = best;
  for (double a = coarse - kCoarseStepPx; a <= coarse + kCoarseStepPx + 1e-9; a += kFineStepPx) {
    consider(a);
  }
  if (width) {
    *width = kCoarseStepPx;
    for (double a = best; a <= best + 4.0; a += kFineStepPx) {
      if (cost(a) > 1.1 * best_cost) {
        *width = a - best;
        break;
      }
    }
  }
  return best;
}

// A half acquisition's axis (a full turn, the axis near one end of the detector: the two
// halves of the turn see the two sides of the object, and a view and its opposite overlap only
// in the few columns around the axis). The absolute mismatch cannot look there: a few columns
// of air beside the detector's end match their mirror image as well as the true axis's whole
// overlap does. Relative to the spread of the readings compared, air matches at about 1 (noise
// against noise) and the true axis near 0.
double relative_cost_at(std::span<const LinePair> lines, std::size_t n, double axis) {
  return mismatch_at(lines, n, axis).relative();
}

// The columns a view and its opposite must share for an axis near an end to count: a
// twentieth of the detector, at least 16.
std::size_t least_overlap(std::size_t n_u) { return std::max<std::size_t>(16, n_u / 20); }

// The best axis beyond the central search (kCentreSearchShare either way of the middle), in
// the outer parts where the pair still overlaps by least_overlap columns, by the relative
// mismatch: the axis and its relative cost; nullopt where nothing is searched.
std::optional<std::pair<double, double>> best_outer_axis(std::span<const LinePair> lines,
                                                         std::size_t n_u) {
  const double n = static_cast<double>(n_u);
  const double centre = 0.5 * (n - 1.0);
  const double reach = 0.5 * static_cast<double>(least_overlap(n_u) - 1);
  auto cost = [&](double a) { return relative_cost_at(lines, n_u, a); };
  double best = 0.0, best_cost = std::numeric_limits<double>::infinity();
  auto consider = [&](double a) {
    const double c = cost(a);
    if (c < best_cost) {
      best_cost = c;
      best = a;
    }
  };
  for (double a = reach; a < centre - kCentreSearchShare * n; a += kCoarseStepPx) consider(a);
  for (double a = n - 1.0 - reach; a > centre + kCentreSearchShare * n; a -= kCoarseStepPx) consider(a);
  if (!std::isfinite(best_cost)) return std::nullopt;
  const double coarse = best;
  for (double a = coarse - kCoarseStepPx; a <= coarse + kCoarseStepPx + 1e-9; a += kFineStepPx) {
    if (a >= reach && a <= n - 1.0 - reach) consider(a);
  }
  return std::pair{best, best_cost};
}

// An outer axis is taken over the central one only when it matches this much better,
// relatively: a centred scan's outer overlap is mostly air (relative cost about 1, its true
// axis a few hundredths); a half acquisition's central search pairs different parts of the
// object (about 1 or more), its true axis a few hundredths.
constexpr double kOuterAxisAdvantage = 0.25;

}  // namespace

namespace {

// The view-pair estimate (offset, axis, spread, pairs, rows); nullopt without a pair.
std::optional<CentreEstimate> from_view_pairs(const Scan& scan) {
  const Geometry& g = scan.geometry;
  std::vector<ViewPair> all = opposite_views(g.angles);
  if (all.empty()) return std::nullopt;
  std::vector<ViewPair> pairs;
  for (std::size_t i : evenly(all.size(), kMostPairs)) pairs.push_back(all[i]);
  const std::vector<std::size_t> rows = evenly(g.is_3d() ? g.n_v : 1, preprocessing::kCentreRows);

  CentreEstimate e;
  e.pairs = pairs.size();
  e.rows = rows.size();
  double width = 0.0;
  const std::vector<LinePair> lines = line_pairs(scan, pairs, rows);
  e.axis_column = best_axis(lines, g.n_u, &width);
  if (covers_full_turn(g)) {
    const std::optional<std::pair<double, double>> outer = best_outer_axis(lines, g.n_u);
    if (outer && outer->second < kOuterAxisAdvantage * relative_cost_at(lines, g.n_u, e.axis_column)) {
      e.axis_column = outer->first;
      e.half_acquisition = true;
    }
  }
  e.offset_px = 0.5 * (static_cast<double>(g.n_u) - 1.0) - e.axis_column;
  if (pairs.size() == 1) {
    e.spread_px = width;
  } else {
    double sum2 = 0.0;
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      const std::span<const LinePair> one(lines.data() + p * rows.size(), rows.size());
      const std::optional<std::pair<double, double>> outer =
          e.half_acquisition ? best_outer_axis(one, g.n_u) : std::nullopt;
      const double a = outer ? outer->first : best_axis(one, g.n_u);
      sum2 += (a - e.axis_column) * (a - e.axis_column);
    }
    e.spread_px = std::sqrt(sum2 / static_cast<double>(pairs.size()));
  }
  return e;
}

// A fan's (a cone's through the source's plane) axis from conjugate rays; as estimate_from.
CentreEstimate estimate_from_conjugates(const Scan& as_read, const Scan& scan) {
  const Geometry& g = scan.geometry;
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  const bool cone = g.type == GeometryType::kCone3d;
  if (cone && !preprocessing::source_plane_on_detector(g)) {
    throw InputError(
        "the source's plane projects off the detector's rows (a band of rows cut off the "
        "middle?): no row holds the conjugate rays to find the centre from; pass the offset "
        "with --offset-px");
  }
  const Scan fan =
      preprocessing::in_angle_order(cone ? preprocessing::midplane_fan(as_read) : as_read);
  const Scan fan_compared =
      preprocessing::in_angle_order(cone ? preprocessing::midplane_fan(scan) : scan);
  const std::optional<preprocessing::ConjugateAxis> axis =
      preprocessing::conjugate_axis(fan, fan_compared);
  // A cone's rows about the source's plane unread or flat (the rest of the scan may not be),
  // after the geometry's own reasons.
  if (cone && (axis || (g.n_u >= 8 && covers_full_turn(g))) &&
      !preprocessing::holds_structure(fan.measurement)) {
    throw InputError(
        "the detector rows through the source's plane, where conjugate rays meet, read no two "
        "different finite values: nothing to find the centre from; pass the offset with "
        "--offset-px");
  }
  if (!axis) {
    throw InputError(
        "centre finding in a fan or cone beam needs views that step evenly over a full turn "
        "and a detector of at least 8 elements; pass the offset with --offset-px");
  }
  if (axis->at_search_end) {
    char line[300];
    std::snprintf(line, sizeof(line),
                  "conjugate rays match best at the end of the search, %.1f px from the "
                  "geometry's offset: the axis lies beyond, or the readings do not show the "
                  "object turning; pass the offset with --offset-px",
                  std::fabs(axis->offset_px - g.offset_u));
    throw InputError(line);
  }
  // Conjugates paired the wrong way round match best at a confident wrong axis (16 px off
  // on the paper's fan): the sense is read about the geometry's offset and the one found.
  std::vector<double> offsets{g.offset_u};
  if (std::fabs(axis->offset_px - g.offset_u) > 1.0) offsets.push_back(axis->offset_px);
  for (const double offset : offsets) {
    if (std::optional<std::string> doubt =
            preprocessing::reversed_fan_doubt(fan_compared, offset)) {
      throw InputError("no centre: " + *doubt);
    }
  }
  CentreEstimate e;
  e.offset_px = axis->offset_px;
  e.axis_column = 0.5 * (static_cast<double>(g.n_u) - 1.0) - e.offset_px;
  e.rows = 1;
  e.pairs = axis->rays;
  e.half_acquisition = axis->half_acquisition;
  e.method = axis->half_acquisition ? "conjugate rays, half acquisition" : "conjugate rays";
  e.sinogram_offset_px = kNaN;
  e.pairs_offset_px = kNaN;
  return e;
}

// estimate_centre before the check of the readings (the geometry's reasons come first):
// `as_read` the readings, `scan` those the methods compare (compared()).
CentreEstimate estimate_from(const Scan& as_read, const Scan& scan) {
  const Geometry& g = scan.geometry;
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (g.is_divergent()) return estimate_from_conjugates(as_read, scan);
  if (g.n_u < 8) throw InputError("centre finding needs a detector of at least 8 elements");
  // Pairs half a turn apart by angles of the wrong range match best at a confident wrong axis.
  if (std::optional<std::string> doubt =
          angular_range_doubt(preprocessing::read_prepared_angular_range(as_read))) {
    throw InputError("no centre: " + *doubt);
  }
  // An interleaved acquisition (0, 2, 4, ... degrees, then 1, 3, 5, ...) is a half-turn in
  // angle order: the sinogram needs its views in order (it was "no evenly spaced half-turn").
  const Scan ordered = preprocessing::in_angle_order(scan);
  const std::optional<CentreEstimate> pairs = from_view_pairs(ordered);
  std::optional<preprocessing::SinogramAxis> sinogram = preprocessing::sinogram_axis(ordered);
  const bool no_minimum = sinogram && sinogram->rows == 0;
  if (no_minimum) sinogram.reset();
  if (!pairs && !sinogram) {
    if (!preprocessing::holds_structure(scan.measurement)) throw_without_structure();
    if (no_minimum) {
      throw InputError(
          "the whole sinogram matches its mirror image best at an end of the search (the axis "
          "within " +
          std::to_string(static_cast<int>(std::lround(kCentreSearchShare * 100))) +
          "% of the detector's width of its middle): the axis lies beyond, or the readings do "
          "not show the object turning; pass the offset with --offset-px");
    }
    throw InputError(
        "the views cover no evenly spaced half-turn and no two are half a turn apart (or either "
        "side of it); pass the offset with --offset-px");
  }
  CentreEstimate e = pairs ? *pairs : CentreEstimate{};
  e.pairs_offset_px = pairs ? pairs->offset_px : kNaN;
  e.method = e.half_acquisition ? "view pairs, half acquisition" : "view pairs";
  e.sinogram_offset_px = kNaN;
  // The sinogram's search is the central one: a half acquisition's axis is the pairs'.
  if (sinogram && !e.half_acquisition) {
    e.method = "sinogram";
    e.axis_column = sinogram->axis_column;
    e.offset_px = 0.5 * (static_cast<double>(g.n_u) - 1.0) - e.axis_column;
    e.sinogram_offset_px = e.offset_px;
    e.rows = sinogram->rows;
  }
  return e;
}

}  // namespace

bool centre_search_covers(const Geometry& g) {
  if (g.is_divergent() || covers_full_turn(g)) return true;
  return std::fabs(g.offset_u) <= kCentreSearchShare * static_cast<double>(g.n_u);
}

CentreEstimate estimate_centre(const Scan& scan) {
  check_array(scan.measurement, "the centre's scan");
  if (!preprocessing::holds_structure(scan.measurement)) {
    (void)estimate_from(scan, scan);  // the geometry's reasons first
    throw_without_structure();
  }
  // A large 3D scan is read on the rows the methods use: the elements left out below would
  // otherwise copy all of it (a whole scan that fits in memory, doubled).
  const Scan read = preprocessing::prepared(scan);
  return estimate_from(read, preprocessing::compared(read));
}

}  // namespace riner
