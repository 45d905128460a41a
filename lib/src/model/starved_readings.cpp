#include "model/starved_readings.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "model/response_changes.hpp"
#include "riner/rays.hpp"
#include "riner/scan.hpp"

namespace riner::model {

namespace {

// Each element's runs of at least `views_needed` consecutive views reading +inf, [first, end).
using DarkRuns = std::vector<std::vector<std::pair<std::size_t, std::size_t>>>;
DarkRuns long_dark_runs(const Array& m, std::size_t views, std::size_t views_needed) {
  const std::size_t per_view = m.size() / views;
  DarkRuns out(per_view);
  for (std::size_t e = 0; e < per_view; ++e) {
    for (std::size_t v = 0; v < views;) {
      if (!is_starved(m.data[v * per_view + e])) {
        ++v;
        continue;
      }
      std::size_t w = v;
      while (w < views && is_starved(m.data[w * per_view + e])) ++w;
      if (w - v >= views_needed) out[e].emplace_back(v, w);
      v = w;
    }
  }
  return out;
}

// The long dark run of element e that holds view v; nullopt where none does.
std::optional<std::pair<std::size_t, std::size_t>> dark_run_at(const DarkRuns& runs, std::size_t e,
                                                               std::size_t v) {
  for (const auto& r : runs[e]) {
    if (r.first <= v && v < r.second) return r;
  }
  return std::nullopt;
}

// Elements that read nothing finite in any view, a run of which more than kWidestDeadRun are
// dark (+inf), centred on the rotation axis (within kAxisRunTolerance of `axis_column`),
// beside which, in kAxisEdgeShare of the views with light or more, the element on either side
// is dark (where it is a dense edge, as below, in most of its other views: not an element
// dying part-way, or starved now and then at a thick body's middle), or reads `bar` or more
// and a step of kAxisEdgeStep above the median of the kAxisBeyond readings beyond it: the beam
// stopped on the axis in every view by something far denser than what lies around it (a metal
// pin there, its edges' elements lit by a few photons, or dark, view by view). `bar` and the
// step are shares of the views' typical largest reading (the median over views of each one's
// largest: one spike moved the scan's largest and lost a pin). A dead element or module off
// the axis leaves its conjugate rays, across the axis, lit; a lone dead element on the axis
// stays dead (a bound there would draw a dense dot), and so do dead elements on the axis of a
// thick body, whose rays beside them read as much as those beyond (a review's disc of
// 0.14/mm at 10^4 photons, its rays beside them dark now and then: bounds at the largest, a
// noisy reading above its middle's, made that 0.46), or beside elements dying part-way (a
// review's: 3.67/mm for 0.05). Not told apart: a hollow capillary on the axis whose lumen a
// dead module covers exactly, and metal whose edges read as the body beside it in a quarter
// of the views (photon-starved scans: at 10^4 photons a pin's edges are dark or the body's).
constexpr double kAxisRunTolerance = 1.0;
constexpr double kAxisEdgeShare = 0.75;
constexpr double kAxisEdgeStep = 0.25;
constexpr long kAxisBeyond = 3;
std::vector<char> stopped_on_axis(const Array& m, std::size_t views, double axis_column,
                                  float typical, float floor) {
  const std::size_t per_view = m.size() / views;
  std::vector<char> out(per_view, 0);
  if (!std::isfinite(axis_column) || !(typical > 0.0f)) return out;
  const auto n = static_cast<long>(m.shape.back());
  const std::size_t rows = per_view / static_cast<std::size_t>(n);
  // Unread in every view (NaN or +inf), and dark (+inf) in some.
  std::vector<char> unread(per_view, 1), dark(per_view, 0);
  for (std::size_t i = 0; i < m.size(); ++i) {
    if (std::isfinite(m.data[i])) unread[i % per_view] = 0;
    if (is_starved(m.data[i])) dark[i % per_view] = 1;
  }
  const float bar = static_cast<float>(kStarvedNeighbourShare) * typical;
  const float step = static_cast<float>(kAxisEdgeStep) * typical;
  // The element beside the run at `at` in a view's line, lit: a reading of `bar` or more, a
  // step above the readings beyond it (stepping by `dir`).
  const auto lit_edge = [&](const float* line, long at, long dir) {
    if (!(line[at] >= bar)) return false;
    std::vector<float> beyond;
    for (long j = at + dir; j >= 0 && j < n && beyond.size() < kAxisBeyond; j += dir) {
      if (std::isfinite(line[j])) beyond.push_back(line[j]);
    }
    if (beyond.empty()) return false;
    std::nth_element(beyond.begin(), beyond.begin() + beyond.size() / 2, beyond.end());
    return line[at] - beyond[beyond.size() / 2] >= step;
  };
  // Whether the element at `at` of row `first` is a dense edge in most views where it is lit
  // (a metal's edge lit by a few photons now and then; one dying part-way, or starved now and
  // then at a thick body's middle, read as what lies beyond it before): its dark views count.
  const auto dark_counts = [&](std::size_t first, long at, long dir) {
    std::size_t lit = 0, dense = 0;
    for (std::size_t v = 0; v < views; ++v) {
      const float* line = m.ptr() + v * per_view + first;
      if (!std::isfinite(line[at])) continue;
      ++lit;
      dense += lit_edge(line, at, dir);
    }
    return 2 * dense >= lit;
  };
  const auto edge = [&](const float* line, long at, long dir, bool dark_dense) {
    return is_starved(line[at]) ? dark_dense : lit_edge(line, at, dir);
  };
  // The median of the element's finite readings; NaN where it has none.
  const auto lit_median = [&](std::size_t e) {
    std::vector<float> lit;
    for (std::size_t v = 0; v < views; ++v) {
      const float x = m.data[v * per_view + e];
      if (std::isfinite(x)) lit.push_back(x);
    }
    if (lit.empty()) return NAN;
    std::nth_element(lit.begin(), lit.begin() + lit.size() / 2, lit.end());
    return lit[lit.size() / 2];
  };
  // The bounds go at the scan's largest reading: the edges, lit, must read near it, as a
  // metal's do (a count-limited beam), not a bone rod's far below a plate's edge-on rays (a
  // review's: its dead module's bounds at 7.14 drew 1.36/mm for 0.18).
  const auto near_floor = [&](std::size_t e) {
    return lit_median(e) >= static_cast<float>(kStarvedNeighbourShare) * floor;
  };
  for (std::size_t r = 0; r < rows; ++r) {
    const std::size_t first = r * static_cast<std::size_t>(n);
    for (long k = 0; k < n;) {
      if (!unread[first + static_cast<std::size_t>(k)]) {
        ++k;
        continue;
      }
      long end = k;
      std::size_t darks = 0;
      for (; end < n && unread[first + static_cast<std::size_t>(end)]; ++end) {
        darks += dark[first + static_cast<std::size_t>(end)];
      }
      const double centre = 0.5 * static_cast<double>(k + end - 1);
      if (darks > kWidestDeadRun && k > 0 && end < n &&
          std::fabs(centre - axis_column) <= kAxisRunTolerance &&
          near_floor(first + static_cast<std::size_t>(k - 1)) &&
          near_floor(first + static_cast<std::size_t>(end))) {
        const bool left_dense = dark_counts(first, k - 1, -1);
        const bool right_dense = dark_counts(first, end, 1);
        std::size_t lit = 0, dense = 0;
        for (std::size_t v = 0; v < views; ++v) {
          const float* line = m.ptr() + v * per_view + first;
          if (std::none_of(line, line + n, [](float x) { return std::isfinite(x); })) continue;
          ++lit;  // a blank frame says nothing
          dense += edge(line, k - 1, -1, left_dense) && edge(line, end, 1, right_dense);
        }
        if (static_cast<double>(dense) >= kAxisEdgeShare * static_cast<double>(lit)) {
          std::fill(out.begin() + static_cast<std::ptrdiff_t>(first) + k,
                    out.begin() + static_cast<std::ptrdiff_t>(first) + end, 1);
        }
      }
      k = end;
    }
  }
  return out;
}

// The +inf readings of traces that move across the detector with the views, as the beam a
// dense object off the axis stops does, view after view: within each detector row, runs of +inf
// joined across neighbouring views (touching diagonally too) that span kLeastTraceViews views or
// more (and a kTraceViewShare-th of the views), about one run a view, and whose elements shift by
// kLeastTraceShift or more beyond the widest run's width. A thin wire's trace is a run of one or
// two elements whose neighbours, partly covered, read far below the largest (a 2.6-px wire of 10/mm
// at 10^6 photons: beside it 0.8-5 for a largest of 13.8, its 142 readings taken for dead elements,
// 27 live elements flagged dead and the wire read as air). A dead element, a module, a glitch of a
// few views or a blank frame does not move, and the runs kept follow one point's projection in
// kTraceOnPathShare of the views the trace spans (fit_trace_point), one point after another
// (kMostTracePoints: two wires' traces cross in every half turn, and join). Left out: elements that
// read nothing, lines with no light, and an element's long dark run from the scan's start or to its
// end (an element dying beside a trace would join it). Light and noise alternating along a wide
// metal's trace under a dim beam (flats of 300 counts over a dark noise of 8) break it into
// pieces that follow no one path (as bounds beside readings of noise they drew streaks: the
// body's error 0.048 -> 0.071), and more than kMostRunsPerTraceView runs a view per point are
// not looked at. A trace spans a quarter of the scan's views or more: a wire stops the beam in
// every view, where photon starvation's noise under a dim beam (no light by chance in a thick
// body's rays) chains its dark readings over 11-21 views of 90 (bounds far above those rays'
// integrals).
constexpr std::size_t kLeastTraceViews = 8;
constexpr std::size_t kTraceViewShare = 4;
constexpr long kLeastTraceShift = 2;
constexpr double kMostRunsPerTraceView = 1.25;
// Traces told apart in one component, one point's path at a time.
constexpr std::size_t kMostTracePoints = 4;
// The least sweep of a trace's point across the detector, in elements: a dead element that
// drifts 4-6 px about the axis column (registration shifts, a runout correction) follows a point
// within 3 px of the axis as closely as a wire (a review's: a fake dot of 6-9 /mm there, the
// body's error 0.018 -> 0.20). A wire within 5 px of the axis stays unread, as before.
constexpr double kLeastTraceSweep = 10.0;
// The share of the views a trace spans in which a run lies on one point's path.
constexpr double kTraceOnPathShare = 0.9;
// The point in the volume's plane whose projection best follows `centres` (a run's middle
// column in each of `at` views): a coarse grid over 1.5 times the volume's extent scored by the
// lower quartile of the misses, then Gauss-Newton on the runs within kTraceFitTolerance * 3 of it.
// u does not depend on z in the geometries riner reads (parallel, fan, cone with a flat detector).
struct TraceFit {
  double x = 0.0, y = 0.0;
};
constexpr double kTraceFitTolerance = 1.0;  // elements between a run's middle and the point's
constexpr int kTraceGrid = 64;
constexpr std::size_t kTraceCoarseRuns = 48;
TraceFit fit_trace_point(const Geometry& g, const std::vector<std::size_t>& at,
                         const std::vector<double>& centres) {
  const auto miss = [&](std::size_t i, double x, double y) {
    return centres[i] - project_to_detector(g, at[i], Vec3{x, y, 0.0}).u;
  };
  const std::size_t ny = g.volume_shape[g.volume_shape.size() - 2], nx = g.volume_shape.back();
  const double half = 0.75 * g.voxel_mm * static_cast<double>(std::max(nx, ny));
  const std::size_t stride = std::max<std::size_t>(1, at.size() / kTraceCoarseRuns);
  TraceFit best;
  double best_score = INFINITY;
  std::vector<double> misses;
  for (int j = 0; j <= kTraceGrid; ++j) {
    for (int i = 0; i <= kTraceGrid; ++i) {
      const double x = -half + 2.0 * half * i / kTraceGrid, y = -half + 2.0 * half * j / kTraceGrid;
      misses.clear();
      for (std::size_t k = 0; k < at.size(); k += stride)
        misses.push_back(std::fabs(miss(k, x, y)));
      // A low quantile: the runs of other points' traces in the component miss by far.
      const auto quantile = misses.begin() + static_cast<std::ptrdiff_t>(misses.size() / 4);
      std::nth_element(misses.begin(), quantile, misses.end());
      if (*quantile < best_score) best_score = *quantile, best = {x, y};
    }
  }
  const double h = 1e-3 * g.voxel_mm;
  for (int round = 0; round < 10; ++round) {
    double a11 = 0.0, a12 = 0.0, a22 = 0.0, b1 = 0.0, b2 = 0.0;
    for (std::size_t k = 0; k < at.size(); ++k) {
      const double r = miss(k, best.x, best.y);
      if (std::fabs(r) > 3.0 * kTraceFitTolerance) continue;
      const double dx = (miss(k, best.x + h, best.y) - r) / h;
      const double dy = (miss(k, best.x, best.y + h) - r) / h;
      a11 += dx * dx, a12 += dx * dy, a22 += dy * dy, b1 += dx * r, b2 += dy * r;
    }
    const double det = a11 * a22 - a12 * a12;
    if (!(std::fabs(det) > 0.0)) break;
    best.x -= (a22 * b1 - a12 * b2) / det;
    best.y -= (a11 * b2 - a12 * b1) / det;
  }
  return best;
}

// Returns the indices of the readings kept, sorted: few, where a mask would take a quarter of
// the readings' memory on every scan with a dead element.
std::vector<std::size_t> moving_traces(const Array& m, std::size_t views,
                                       const std::vector<char>& reads, const DarkRuns& dark,
                                       const Geometry& g) {
  const std::size_t per_view = m.size() / views;
  const auto n = static_cast<long>(m.shape.back());
  const std::size_t rows = per_view / static_cast<std::size_t>(n);
  std::vector<std::size_t> out;
  const auto counts = [&](std::size_t v, std::size_t e) {
    if (!is_starved(m.data[v * per_view + e]) || !reads[e]) return false;
    const auto run = dark_run_at(dark, e, v);
    return !(run && (run->first == 0 || run->second == views));
  };
  struct Run {
    std::size_t view;
    long first, end;
  };
  for (std::size_t r = 0; r < rows; ++r) {
    const std::size_t row = r * static_cast<std::size_t>(n);
    std::vector<Run> found;
    std::vector<std::size_t> view_start(views + 1, 0);
    for (std::size_t v = 0; v < views; ++v) {
      view_start[v] = found.size();
      const float* line = m.ptr() + v * per_view + row;
      if (std::none_of(line, line + n, [](float x) { return std::isfinite(x); })) continue;
      for (long k = 0; k < n;) {
        if (!counts(v, row + static_cast<std::size_t>(k))) {
          ++k;
          continue;
        }
        long end = k;
        while (end < n && counts(v, row + static_cast<std::size_t>(end))) ++end;
        found.push_back({v, k, end});
        k = end;
      }
    }
    view_start[views] = found.size();
    if (found.empty()) continue;
    std::vector<std::size_t> parent(found.size());
    for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = i;
    const auto root = [&](std::size_t i) {
      while (parent[i] != i) i = parent[i] = parent[parent[i]];
      return i;
    };
    for (std::size_t v = 1; v < views; ++v) {
      for (std::size_t i = view_start[v]; i < view_start[v + 1]; ++i) {
        for (std::size_t j = view_start[v - 1]; j < view_start[v]; ++j) {
          if (found[j].first <= found[i].end && found[i].first <= found[j].end) {
            parent[root(i)] = root(j);
          }
        }
      }
    }
    struct Extent {
      std::size_t first_view = SIZE_MAX, last_view = 0, runs = 0;
      long first = LONG_MAX, end = LONG_MIN, widest = 0;
    };
    std::map<std::size_t, Extent> extent;
    for (std::size_t i = 0; i < found.size(); ++i) {
      Extent& x = extent[root(i)];
      x.first_view = std::min(x.first_view, found[i].view);
      x.last_view = std::max(x.last_view, found[i].view);
      x.first = std::min(x.first, found[i].first);
      x.end = std::max(x.end, found[i].end);
      x.widest = std::max(x.widest, found[i].end - found[i].first);
      ++x.runs;
    }
    const std::size_t least_views = std::max(kLeastTraceViews, views / kTraceViewShare);
    std::map<std::size_t, std::vector<std::size_t>> members;
    for (std::size_t i = 0; i < found.size(); ++i) {
      const Extent& x = extent[root(i)];
      const std::size_t spanned = x.last_view - x.first_view + 1;
      if (spanned < least_views) continue;
      if (x.end - x.first - x.widest < kLeastTraceShift) continue;
      if (static_cast<double>(x.runs) >
          kMostRunsPerTraceView * static_cast<double>(kMostTracePoints * spanned)) {
        continue;
      }
      members[root(i)].push_back(i);
    }
    // A trace is a fixed object's: its runs follow one point's projection, view after view (a
    // dead element that drifts across the detector, as in projections shifted to correct a
    // drift, moved and joined too: the review's pin scene read 0.39/mm of error for 0.01).
    // Only the runs on that path are kept (an element dark for some views beside it is not).
    for (const auto& [component, runs] : members) {
      const Extent& x = extent[component];
      const std::size_t spanned = x.last_view - x.first_view + 1;
      // Each point in turn: the traces of two wires in a slice cross (two sinusoids meet once
      // in half a turn) and join into one component.
      std::vector<char> taken(runs.size(), 0);
      for (std::size_t point_index = 0; point_index < kMostTracePoints; ++point_index) {
        std::vector<std::size_t> left, at;
        std::vector<double> centres;
        for (std::size_t k = 0; k < runs.size(); ++k) {
          if (taken[k]) continue;
          left.push_back(k);
          at.push_back(found[runs[k]].view);
          centres.push_back(0.5 *
                            static_cast<double>(found[runs[k]].first + found[runs[k]].end - 1));
        }
        if (left.size() < least_views) break;
        const TraceFit point = fit_trace_point(g, at, centres);
        std::vector<std::size_t> on_path, path_views;
        for (std::size_t k = 0; k < left.size(); ++k) {
          const double u = project_to_detector(g, at[k], Vec3{point.x, point.y, 0.0}).u;
          if (std::fabs(centres[k] - u) > kTraceFitTolerance) continue;
          on_path.push_back(left[k]);
          path_views.push_back(at[k]);
        }
        if (on_path.empty()) break;
        std::sort(path_views.begin(), path_views.end());
        path_views.erase(std::unique(path_views.begin(), path_views.end()), path_views.end());
        // Runs that follow no trace (a dead element drifting beside it, picked first) are set
        // aside and the next point is looked for among the rest; a path that sweeps less than
        // kLeastTraceSweep elements is a point near the axis, which a dead element drifting a
        // few pixels about the axis, or corrected for a runout there, follows as well. The sweep
        // is over the whole scan: a trace cut by a dead element spans part of it.
        double nearest = INFINITY, farthest = -INFINITY;
        for (std::size_t v = 0; v < views; ++v) {
          const double u = project_to_detector(g, v, Vec3{point.x, point.y, 0.0}).u;
          nearest = std::min(nearest, u);
          farthest = std::max(farthest, u);
        }
        const bool trace = path_views.size() >= kTraceOnPathShare * static_cast<double>(spanned) &&
                           farthest - nearest >= kLeastTraceSweep;
        for (std::size_t k : on_path) taken[k] = 1;
        if (!trace) continue;
        for (std::size_t k : on_path) {
          const Run& run = found[runs[k]];
          const std::size_t at_line = run.view * per_view + row;
          for (long e = run.first; e < run.end; ++e) {
            out.push_back(at_line + static_cast<std::size_t>(e));
          }
        }
      }
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

float nearest_finite(const float* line, long from, long step, long n) {
  for (long k = from; k >= 0 && k < n; k += step) {
    if (std::isfinite(line[k])) return line[k];
  }
  return NAN;
}

StarvedReadings mark_starved_readings(Array& measurement, std::size_t views, double axis_column,
                                      const Geometry* geometry) {
  StarvedReadings out;
  if (measurement.size() == 0 || views == 0 || measurement.rank() < 2) return out;
  // Most scans have no reading of +inf: nothing to tell apart (FBP of a large stack paid for
  // the runs below on every slab).
  if (std::none_of(measurement.data.begin(), measurement.data.end(), is_starved)) return out;
  const float limit = largest_reading(measurement, views);
  // The rules below weigh readings against the scan's largest (a plate's edge-on rays in one
  // view are real, and tell a bone rod's edges from a metal's). The bounds go at each view's
  // largest finite reading, high among the views but not the highest (kFloorViewQuantile): one
  // bad reading under the corrupt limit set the floor of every bound (a review's 100 made a
  // 3/mm disc read 23.6 and FBP's 11.4), where a metal's edges read near it in most views.
  // Each view's largest finite reading (of the views with one above 0): their largest, the
  // median (the axis rule's typical) and the floor's quantile, from one pass.
  const std::size_t per_view_all = measurement.size() / views;
  std::vector<float> view_largest;
  float largest = 0.0f;
  for (std::size_t v = 0; v < views; ++v) {
    float top = 0.0f;
    for (std::size_t i = 0; i < per_view_all; ++i) {
      const float x = measurement.data[v * per_view_all + i];
      if (std::isfinite(x) && std::fabs(x) <= limit) top = std::max(top, x);
    }
    if (top > 0.0f) view_largest.push_back(top);
    largest = std::max(largest, top);
  }
  float floor = largest;
  float typical = 0.0f;
  if (!view_largest.empty()) {
    const auto middle = view_largest.begin() + static_cast<std::ptrdiff_t>(view_largest.size() / 2);
    std::nth_element(view_largest.begin(), middle, view_largest.end());
    typical = *middle;
    const auto at = view_largest.begin() +
                    static_cast<std::ptrdiff_t>(kFloorViewQuantile *
                                                static_cast<double>(view_largest.size() - 1));
    std::nth_element(view_largest.begin(), at, view_largest.end());
    floor = *at;
  }
  const auto n = static_cast<long>(measurement.shape.back());
  const std::size_t lines = measurement.size() / static_cast<std::size_t>(n);
  const std::size_t per_view = measurement.size() / views;
  // An element that reads nothing in any view is dead, whatever its neighbours read.
  std::vector<char> reads(per_view, 0);
  for (std::size_t i = 0; i < measurement.size(); ++i) {
    if (std::isfinite(measurement.data[i])) reads[i % per_view] = 1;
  }
  const DarkRuns dark = long_dark_runs(measurement, views, response_change_min_views(views));
  const float bar = static_cast<float>(kStarvedNeighbourShare) * largest;
  const std::vector<char> on_axis =
      stopped_on_axis(measurement, views, axis_column, typical, largest);
  const std::vector<std::size_t> moving =
      geometry ? moving_traces(measurement, views, reads, dark, *geometry)
               : std::vector<std::size_t>();
  for (std::size_t l = 0; l < lines; ++l) {
    const std::size_t at = l * static_cast<std::size_t>(n);
    float* line = measurement.ptr() + at;
    for (long k = 0; k < n;) {
      if (!is_starved(line[k])) {
        ++k;
        continue;
      }
      long end = k;
      while (end < n && is_starved(line[end])) ++end;
      const float left = nearest_finite(line, k - 1, -1, n),
                  right = nearest_finite(line, end, 1, n);
      // A line with no finite reading (a blank frame, a lost view) says nothing of the object.
      const bool blank = std::isnan(left) && std::isnan(right);
      const bool wide = static_cast<std::size_t>(end - k) > kWidestDeadRun;
      const bool dense_beside = left >= bar || right >= bar;
      // Each element's long dark run here, if any: an element dying part-way (to the scan's end,
      // or alive only from some view) is no metal, nor is a block of kWidestDeadRun + 1 or more
      // in the run dying at one view (a module failing: an audit's 8 elements dark from view 100
      // on were read as metal, bright bands and the error outside x7); metal's band moves with
      // the views, its elements going dark at different ones.
      const std::size_t view =
          (at / static_cast<std::size_t>(n)) / (per_view / static_cast<std::size_t>(n));
      std::vector<std::optional<std::pair<std::size_t, std::size_t>>> runs;
      std::map<std::pair<std::size_t, std::size_t>, std::size_t> together;
      for (long j = k; j < end; ++j) {
        runs.push_back(dark_run_at(dark, (at + static_cast<std::size_t>(j)) % per_view, view));
        if (runs.back()) ++together[*runs.back()];
      }
      // The module's runs: kWidestDeadRun + 1 or more elements dark from one view to the end
      // (or from the start to one view).
      std::vector<std::pair<std::size_t, std::size_t>> module;
      for (const auto& [r, count] : together) {
        if ((r.first == 0 || r.second == views) && count > kWidestDeadRun) module.push_back(r);
      }
      // An element of the run dark throughout a module's run is of the module too: one the
      // metal's trace had darkened just before the module failed starts its run earlier (an
      // audit's scan: that element alone was kept as 80 bounds, the error outside the metal x4).
      const auto of_module = [&](const std::pair<std::size_t, std::size_t>& r) {
        return std::any_of(module.begin(), module.end(), [&](const auto& m) {
          return (m.second == views && r.second == views && r.first <= m.first) ||
                 (m.first == 0 && r.first == 0 && r.second >= m.second);
        });
      };
      for (long j = k; j < end; ++j) {
        const std::size_t i = at + static_cast<std::size_t>(j);
        const auto& run = runs[static_cast<std::size_t>(j - k)];
        const bool failing = run && of_module(*run);
        const bool axis = on_axis[i % per_view] != 0;
        const bool stopped =
            !blank && (axis || (!failing && (wide || (dense_beside && !run) ||
                                             std::binary_search(moving.begin(), moving.end(), i))));
        if (largest > 0.0f && stopped && (reads[i % per_view] || axis)) {
          ++out.count;
        } else {
          line[j] = NAN;
        }
      }
      k = end;
    }
  }
  if (out.count > 0) out.floor = floor;
  return out;
}

double axis_column(const Geometry& g) { return project_to_detector(g, 0, Vec3{0.0, 0.0, 0.0}).u; }

StarvedReadings mark_starved_readings(Array& measurement, const Geometry& g) {
  mark_corrupt_readings(measurement, g.n_views());
  return mark_starved_readings(measurement, g.n_views(), axis_column(g), &g);
}

}  // namespace riner::model
