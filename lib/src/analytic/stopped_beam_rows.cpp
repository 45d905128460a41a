#include "analytic/stopped_beam_rows.hpp"

#include <algorithm>
#include <cmath>

#include "model/starved_readings.hpp"
#include "riner/scan.hpp"

namespace riner::analytic {

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
    const model::StarvedReadings stopped = model::mark_starved_readings(row, views, axis);
    out.count += stopped.count;
    if (at_floor && stopped.count > 0) {
      for (float& x : row.data) {
        if (model::is_starved(x)) x = stopped.floor;
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
