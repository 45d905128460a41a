#include "model/starved_readings.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <utility>
#include <vector>

#include "model/response_changes.hpp"
#include "riner/scan.hpp"

namespace riner::model {

namespace {

// The first finite reading from `from` on, stepping by `step` (-1: leftwards); NaN where none.
float nearest_finite(const float* line, long from, long step, long n) {
  for (long k = from; k >= 0 && k < n; k += step) {
    if (std::isfinite(line[k])) return line[k];
  }
  return NAN;
}

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

// Elements that read nothing in any view, a run wider than kWidestDeadRun centred on the
// rotation axis (within kAxisRunTolerance of `axis_column`), whose elements on both sides read
// `bar` or more or nothing (+inf) in kAxisDenseShare of the views or more, and nothing in one
// view at least: the beam stopped on the axis in every view (a metal pin there, its edges'
// elements lit by a few photons, or dark, view by view). A dead element or module off the axis
// leaves its conjugate rays, across the axis, lit; a lone dead element on it stays dead (a
// bound there would draw a dense dot), and so does a dead module on the axis of a thick body
// whose rays beside it never starve (a uniform disc's central rays near the largest: the
// bound at the largest made its middle 11% too dense).
constexpr double kAxisRunTolerance = 1.0;
constexpr double kAxisDenseShare = 0.75;
std::vector<char> stopped_on_axis(const Array& m, std::size_t views, const std::vector<char>& reads,
                                  double axis_column, float bar) {
  const std::size_t per_view = m.size() / views;
  std::vector<char> out(per_view, 0);
  if (!std::isfinite(axis_column)) return out;
  const auto n = static_cast<long>(m.shape.back());
  const std::size_t rows = per_view / static_cast<std::size_t>(n);
  const auto dense_or_dark = [&](float x) { return is_starved(x) || x >= bar; };
  for (std::size_t r = 0; r < rows; ++r) {
    const std::size_t first = r * static_cast<std::size_t>(n);
    for (long k = 0; k < n;) {
      if (reads[first + static_cast<std::size_t>(k)]) {
        ++k;
        continue;
      }
      long end = k;
      while (end < n && !reads[first + static_cast<std::size_t>(end)]) ++end;
      const double centre = 0.5 * static_cast<double>(k + end - 1);
      const bool wide = static_cast<std::size_t>(end - k) > kWidestDeadRun;
      if (wide && k > 0 && end < n && std::fabs(centre - axis_column) <= kAxisRunTolerance) {
        std::size_t dense = 0, dark_left = 0, dark_right = 0;
        for (std::size_t v = 0; v < views; ++v) {
          const float* line = m.ptr() + v * per_view + first;
          dense += dense_or_dark(line[k - 1]) && dense_or_dark(line[end]);
          dark_left += is_starved(line[k - 1]);
          dark_right += is_starved(line[end]);
        }
        if (static_cast<double>(dense) >= kAxisDenseShare * static_cast<double>(views) &&
            dark_left > 0 && dark_right > 0) {
          std::fill(out.begin() + static_cast<std::ptrdiff_t>(first) + k,
                    out.begin() + static_cast<std::ptrdiff_t>(first) + end, 1);
        }
      }
      k = end;
    }
  }
  return out;
}

}  // namespace

StarvedReadings mark_starved_readings(Array& measurement, std::size_t views, double axis_column) {
  StarvedReadings out;
  if (measurement.size() == 0 || views == 0 || measurement.rank() < 2) return out;
  const float limit = largest_reading(measurement, views);
  float largest = 0.0f;
  for (float x : measurement.data) {
    if (std::isfinite(x) && std::fabs(x) <= limit) largest = std::max(largest, x);
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
  const std::vector<char> on_axis = stopped_on_axis(measurement, views, reads, axis_column, bar);
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
        const bool stopped = !blank && (axis || (!failing && (wide || (dense_beside && !run))));
        if (largest > 0.0f && stopped && (reads[i % per_view] || axis)) {
          ++out.count;
        } else {
          line[j] = NAN;
        }
      }
      k = end;
    }
  }
  if (out.count > 0) out.floor = largest;
  return out;
}

}  // namespace riner::model
