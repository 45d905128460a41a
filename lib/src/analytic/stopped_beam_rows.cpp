#include "analytic/stopped_beam_rows.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "model/starved_readings.hpp"
#include "riner/scan.hpp"

namespace riner::analytic {

namespace {

// A metal's edges read a good share of the floor beside its run in most views; a lost tile's
// neighbours read the body (a review's disc scene: the tile's streak gone at 0.3 and 0.75, the
// metal's mean 1.83 at 0.3, 1.51 at 0.75).
constexpr float kFloorBesideShare = 0.3f;

// Each run of stopped-beam readings in a detector line: at the floor where a reading beside it
// reads kFloorBesideShare of the floor or more, or where it covers the rotation axis (metal on
// the axis, whose edges are often dark too), else NaN for the interpolation (a run training
// keeps for its width alone, a lost tile of 16 elements in two views, drew a streak at 16).
void set_runs_at_floor(float* line, std::size_t n, float floor, double axis) {
  const float dense = kFloorBesideShare * floor;
  for (std::size_t k = 0; k < n;) {
    if (!model::is_starved(line[k])) {
      ++k;
      continue;
    }
    std::size_t end = k;
    while (end < n && model::is_starved(line[end])) ++end;
    // The nearest finite reading on either side (NaN where none: no edge).
    const auto length = static_cast<long>(n);
    const bool edge = model::nearest_finite(line, static_cast<long>(k) - 1, -1, length) >= dense ||
                      model::nearest_finite(line, static_cast<long>(end), 1, length) >= dense;
    const bool on_axis = static_cast<double>(k) - 1.0 <= axis && axis <= static_cast<double>(end);
    const float value = edge || on_axis ? floor : std::numeric_limits<float>::quiet_NaN();
    for (std::size_t j = k; j < end; ++j) line[j] = value;
    k = end;
  }
}

}  // namespace

StoppedBeamRows stopped_beam_rows(Array& readings, const Geometry& g, bool at_floor) {
  StoppedBeamRows out;
  if (std::none_of(readings.data.begin(), readings.data.end(), model::is_starved)) return out;
  const std::size_t views = g.n_views();
  const std::size_t n = readings.shape.back();
  const std::size_t rows = readings.size() / (views * n);
  const double axis = model::axis_column(g);
  Array row({views, n});
  for (std::size_t r = 0; r < rows; ++r) {
    bool any = false;
    for (std::size_t v = 0; v < views; ++v) {
      const float* from = readings.ptr() + (v * rows + r) * n;
      std::copy_n(from, n, row.ptr() + v * n);
      any = any || std::any_of(from, from + n, model::is_starved);
    }
    if (!any) continue;
    mark_corrupt_readings(row, views);
    const model::StarvedReadings stopped = model::mark_starved_readings(row, views, axis, &g);
    out.count += stopped.count;
    if (at_floor && stopped.count > 0) {
      for (std::size_t v = 0; v < views; ++v) {
        set_runs_at_floor(row.ptr() + v * n, n, stopped.floor, axis);
      }
      out.largest_floor = std::max(out.largest_floor, stopped.floor);
    }
    for (std::size_t v = 0; v < views; ++v) {
      std::copy_n(row.ptr() + v * n, n, readings.ptr() + (v * rows + r) * n);
    }
  }
  return out;
}

}  // namespace riner::analytic
