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

#include "model/noise_evidence.hpp"
#include "model/stuck_elements.hpp"
#include "preprocessing/centre_conjugate.hpp"
#include "preprocessing/centre_sinogram.hpp"
#include "preprocessing/mismatch_sums.hpp"
#include "riner/angular_range.hpp"
#include "riner/array.hpp"
#include "riner/error.hpp"
#include "riner/rays.hpp"

namespace riner {

namespace {

// Whether the finite readings differ at all (a constant scan would match itself at every
// offset, and the search would report the edge of its range).
bool holds_structure(const Array& measurement) {
  const ArrayStats stats = compute_stats(measurement);
  return stats.max > stats.min;
}

[[noreturn]] void throw_without_structure() {
  throw InputError(
      "the readings are all equal: they hold nothing to find the centre from; pass the offset "
      "with --offset-px");
}

// Enough pairs and rows for a stable sum, few enough to stay a fraction of a second.
constexpr std::size_t kMostPairs = 32;
constexpr std::size_t kMostRows = 24;
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

// A fan's distances are doubted where another source-detector distance, this factor away or
// more, pairs rays with their conjugates this many times better than the geometry's.
constexpr double kDistanceDoubtFactor = 1.1;
constexpr double kDistanceDoubtContrast = 4.0;

}  // namespace

namespace {

// The view-pair estimate (offset, axis, spread, pairs, rows); nullopt without a pair.
std::optional<CentreEstimate> from_view_pairs(const Scan& scan) {
  const Geometry& g = scan.geometry;
  std::vector<ViewPair> all = opposite_views(g.angles);
  if (all.empty()) return std::nullopt;
  std::vector<ViewPair> pairs;
  for (std::size_t i : evenly(all.size(), kMostPairs)) pairs.push_back(all[i]);
  const std::vector<std::size_t> rows = evenly(g.is_3d() ? g.n_v : 1, kMostRows);

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

// A cone beam's rays through the source's plane (z = 0) are a fan: that row of every view (read
// between the two rows around it) as a fan-beam scan with the cone's distances.
Scan midplane_fan(const Scan& cone) {
  const Geometry& g = cone.geometry;
  const double v = std::clamp(project_to_detector(g, 0, Vec3{0.0, 0.0, 0.0}).v, 0.0,
                              static_cast<double>(g.n_v - 1));
  const auto r0 = std::min(static_cast<std::size_t>(v), g.n_v > 1 ? g.n_v - 2 : 0);
  const std::size_t r1 = std::min(r0 + 1, g.n_v - 1);
  const double w = v - static_cast<double>(r0);
  Scan fan;
  fan.geometry = g;
  fan.geometry.type = GeometryType::kFan2d;
  fan.geometry.n_v = 1;
  fan.geometry.offset_v = 0.0;
  fan.geometry.volume_shape = {g.volume_shape[1], g.volume_shape[2]};
  const std::size_t views = g.n_views(), n_u = g.n_u;
  fan.measurement = Array({views, n_u});
  for (std::size_t a = 0; a < views; ++a) {
    const float* row0 = cone.measurement.ptr() + (a * g.n_v + r0) * n_u;
    const float* row1 = cone.measurement.ptr() + (a * g.n_v + r1) * n_u;
    for (std::size_t e = 0; e < n_u; ++e) {
      fan.measurement.data[a * n_u + e] = static_cast<float>((1.0 - w) * row0[e] + w * row1[e]);
    }
  }
  return fan;
}

// A 2D scan's views in order of angle (a shuffled or interleaved acquisition): the conjugate
// rays are read between neighbouring views. The same scan where its angles already run one way.
Scan in_angle_order(Scan scan) {
  const std::vector<double>& a = scan.geometry.angles;
  const bool rising = std::is_sorted(a.begin(), a.end());
  const bool falling = std::is_sorted(a.rbegin(), a.rend());
  if (rising || falling || scan.geometry.is_3d()) return scan;
  std::vector<std::size_t> order(a.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t x, std::size_t y) { return a[x] < a[y]; });
  const std::size_t n_u = scan.geometry.n_u;
  Scan sorted = scan;
  sorted.geometry.uniform_angles.reset();
  for (std::size_t i = 0; i < order.size(); ++i) {
    sorted.geometry.angles[i] = a[order[i]];
    std::copy_n(scan.measurement.ptr() + order[i] * n_u, n_u, sorted.measurement.ptr() + i * n_u);
  }
  return sorted;
}

// A hot or dead element reading a steady value matches its own mirror image only about itself,
// and pulls the axis onto it (a 180-degree scan with one column at 50: the axis at that
// column): such elements are left out, as non-finite ones are. The scan itself where none is.
Scan without_stuck(const Scan& scan) {
  const std::vector<std::uint8_t> stuck =
      model::stuck_elements(scan, model::reading_noise(scan).sigma);
  if (std::find(stuck.begin(), stuck.end(), 1) == stuck.end()) return scan;
  Scan without = scan;
  std::vector<float>& rho = without.measurement.data;
  for (std::size_t e = 0; e < stuck.size(); ++e) {
    if (!stuck[e]) continue;
    for (std::size_t i = e; i < rho.size(); i += stuck.size()) rho[i] = NAN;
  }
  without.non_finite = compute_stats(without.measurement).non_finite();
  return without;
}

// Beyond this many readings a 3D scan's centre is found on the rows its methods use.
constexpr std::size_t kMostCopiedReadings = std::size_t{1} << 25;

// A 3D scan cut to the rows the centre is found on: a cone's four rows about the source's
// plane; a parallel beam's kMostRows evenly spread (each row a slice of its own).
Scan centre_rows(const Scan& scan) {
  const Geometry& g = scan.geometry;
  const std::size_t views = g.n_views(), n_u = g.n_u;
  std::vector<std::size_t> rows;
  Scan cut;
  if (g.type == GeometryType::kCone3d) {
    const double v = std::clamp(project_to_detector(g, 0, Vec3{0.0, 0.0, 0.0}).v, 0.0,
                                static_cast<double>(g.n_v - 1));
    const std::size_t first =
        std::min(static_cast<std::size_t>(std::max(0.0, v - 1.0)), g.n_v > 4 ? g.n_v - 4 : 0);
    const std::size_t count = std::min<std::size_t>(4, g.n_v);
    for (std::size_t r = first; r < first + count; ++r) rows.push_back(r);
    cut.geometry = detector_rows_geometry(g, first, count);
  } else {
    rows = evenly(g.n_v, kMostRows);
    cut.geometry = g;
    cut.geometry.n_v = rows.size();
  }
  cut.measurement = Array({views, rows.size(), n_u});
  for (std::size_t a = 0; a < views; ++a) {
    for (std::size_t i = 0; i < rows.size(); ++i) {
      std::copy_n(scan.measurement.ptr() + (a * g.n_v + rows[i]) * n_u, n_u,
                  cut.measurement.ptr() + (a * rows.size() + i) * n_u);
    }
  }
  cut.non_finite = compute_stats(cut.measurement).non_finite();
  return cut;
}

// Spikes (riner/scan.hpp's largest_reading) left out as unread readings are: five readings of
// 1e5 among readings of 3 moved a fan scan's axis 12 px.
Scan without_spikes(Scan scan) {
  mark_corrupt_readings(scan.measurement, scan.geometry.n_views());
  return scan;
}

// Each detector element's readings less their mean over a full turn. A stripe (an element's
// offset, constant over the views) then reads 0, where a conjugate reading, on another element,
// differs from it by the two elements' offsets at every candidate axis: on ringed scans of a
// faint object (line integrals up to 1.5, responses +-25%) the conjugate rays put a fan's axis
// 1.7 px off, a cone's 1.9, and a parallel half acquisition's on the wrong side (+27.8 px for
// -45). Over a full turn an element and its conjugate see the same lines, so their means agree
// about the true axis: the object's matching is unchanged (those scans: 0.00 px off).
Scan without_element_means(Scan scan) {
  const std::size_t views = scan.geometry.n_views();
  const std::size_t per_view = scan.measurement.size() / views;
  std::vector<double> sum(per_view, 0.0);
  std::vector<std::size_t> count(per_view, 0);
  const std::vector<float>& rho = scan.measurement.data;
  for (std::size_t i = 0; i < rho.size(); ++i) {
    if (std::isfinite(rho[i])) sum[i % per_view] += rho[i], ++count[i % per_view];
  }
  for (std::size_t i = 0; i < rho.size(); ++i) {
    const std::size_t e = i % per_view;
    if (count[e] > 0) scan.measurement.data[i] -= static_cast<float>(sum[e] / count[e]);
  }
  return scan;
}

// The readings the methods compare: a full turn's without its elements' means.
Scan compared(Scan scan) {
  return covers_full_turn(scan.geometry) ? without_element_means(std::move(scan)) : scan;
}

// estimate_centre before the check of the readings (the geometry's reasons come first):
// `as_read` the readings, `scan` those the methods compare (compared()).
CentreEstimate estimate_from(const Scan& as_read, const Scan& scan) {
  const Geometry& g = scan.geometry;
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  if (g.is_divergent()) {
    const bool cone = g.type == GeometryType::kCone3d;
    const Scan fan = in_angle_order(cone ? midplane_fan(as_read) : as_read);
    const Scan fan_compared = in_angle_order(cone ? midplane_fan(scan) : scan);
    const std::optional<preprocessing::ConjugateAxis> axis =
        preprocessing::conjugate_axis(fan, fan_compared);
    // A cone's rows about the source's plane unread or flat (the rest of the scan may not be),
    // after the geometry's own reasons.
    if (cone && (axis || (g.n_u >= 8 && covers_full_turn(g))) &&
        !holds_structure(fan.measurement)) {
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
  if (g.n_u < 8) throw InputError("centre finding needs a detector of at least 8 elements");
  // Pairs half a turn apart by angles of the wrong range match best at a confident wrong axis.
  if (std::optional<std::string> doubt = angular_range_doubt(as_read)) {
    throw InputError("no centre: " + *doubt);
  }
  const std::optional<CentreEstimate> pairs = from_view_pairs(scan);
  std::optional<preprocessing::SinogramAxis> sinogram = preprocessing::sinogram_axis(scan);
  const bool no_minimum = sinogram && sinogram->rows == 0;
  if (no_minimum) sinogram.reset();
  if (!pairs && !sinogram) {
    if (!holds_structure(scan.measurement)) throw_without_structure();
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

std::optional<std::string> fan_distance_doubt(const Scan& scan) {
  const Geometry& g = scan.geometry;
  if (!g.is_divergent() || !holds_structure(scan.measurement)) return std::nullopt;
  const bool cone = g.type == GeometryType::kCone3d;
  Scan prepared = without_spikes(without_stuck(
      g.is_3d() && scan.measurement.size() > kMostCopiedReadings ? centre_rows(scan) : scan));
  prepared = compared(std::move(prepared));
  const Scan fan = in_angle_order(cone ? midplane_fan(prepared) : prepared);
  const std::optional<preprocessing::FanDistanceFit> fit =
      preprocessing::conjugate_fan_distance(fan, g.offset_u);
  if (!fit || std::fabs(std::log(fit->scale)) < std::log(kDistanceDoubtFactor) ||
      fit->cost * kDistanceDoubtContrast > fit->cost_as_given) {
    return std::nullopt;
  }
  const double sdd = g.source_origin_mm + g.origin_detector_mm;
  char line[600];
  std::snprintf(
      line, sizeof(line),
      "the fan's rays meet their conjugates where the source sits %.0f mm from the detector, "
      "%.2f times the geometry's %.0f mm (source_origin_mm %g + origin_detector_mm %g), or "
      "with a detector pitch %.2f times the given %g mm: mismatch %.2f%% of the readings' "
      "spread, %.2f%% as given; check the distances (origin_detector_mm runs from the axis, "
      "not the source) and the pitch (after binning)",
      fit->scale * sdd, fit->scale, sdd, g.source_origin_mm, g.origin_detector_mm, 1.0 / fit->scale,
      g.pitch_u, 100.0 * fit->cost, 100.0 * fit->cost_as_given);
  return std::string(line);
}

bool centre_search_covers(const Geometry& g) {
  if (g.is_divergent() || covers_full_turn(g)) return true;
  return std::fabs(g.offset_u) <= kCentreSearchShare * static_cast<double>(g.n_u);
}

CentreEstimate estimate_centre(const Scan& scan) {
  check_array(scan.measurement, "the centre's scan");
  if (!holds_structure(scan.measurement)) {
    (void)estimate_from(scan, scan);  // the geometry's reasons first
    throw_without_structure();
  }
  // A large 3D scan is read on the rows the methods use: the elements left out below would
  // otherwise copy all of it (a whole scan that fits in memory, doubled).
  if (scan.geometry.is_3d() && scan.measurement.size() > kMostCopiedReadings) {
    const Scan rows = without_spikes(without_stuck(centre_rows(scan)));
    return estimate_from(rows, compared(rows));
  }
  const Scan prepared = without_spikes(without_stuck(scan));
  return estimate_from(prepared, compared(prepared));
}

}  // namespace riner
