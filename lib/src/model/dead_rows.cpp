#include "model/dead_rows.hpp"

#include <cmath>

#include "util/fill_between.hpp"

namespace riner::model {

std::vector<std::size_t> fill_dead_rows(Array& measurement, const Geometry& g) {
  if (!g.is_3d()) return {};
  const std::size_t views = g.n_views(), rows = g.n_v, columns = g.n_u;
  std::vector<bool> dead(rows, true);
  for (std::size_t v = 0; v < views; ++v) {
    for (std::size_t r = 0; r < rows; ++r) {
      if (!dead[r]) continue;
      const float* line = measurement.data.data() + (v * rows + r) * columns;
      for (std::size_t c = 0; c < columns && dead[r]; ++c) dead[r] = !std::isfinite(line[c]);
    }
  }
  std::vector<std::size_t> filled;
  for (std::size_t r = 0; r < rows; ++r) {
    if (dead[r]) filled.push_back(r);
  }
  if (filled.empty() || filled.size() == rows) return {};
  for (std::size_t v = 0; v < views; ++v) {
    std::vector<bool> empty = dead;
    util::fill_between(measurement.data.data() + v * rows * columns, columns, columns, empty);
  }
  return filled;
}

}  // namespace riner::model
