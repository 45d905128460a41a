#include "model/dead_rows.hpp"

#include <cmath>

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
  std::vector<long> live;
  for (std::size_t r = 0; r < rows; ++r) {
    if (dead[r]) {
      filled.push_back(r);
    } else {
      live.push_back(static_cast<long>(r));
    }
  }
  if (filled.empty() || live.empty()) return {};
  for (const std::size_t r : filled) {
    // The nearest live rows below and above r (-1: none).
    long below = -1, above = -1;
    for (const long l : live) {
      if (l < static_cast<long>(r)) below = l;
      if (l > static_cast<long>(r) && above < 0) above = l;
    }
    const float w = below >= 0 && above >= 0 ? static_cast<float>(static_cast<long>(r) - below) /
                                                   static_cast<float>(above - below)
                                             : 0.0f;
    for (std::size_t v = 0; v < views; ++v) {
      float* line = measurement.data.data() + (v * rows + r) * columns;
      const float* low = below >= 0 ? measurement.data.data() +
                                          (v * rows + static_cast<std::size_t>(below)) * columns
                                    : nullptr;
      const float* high = above >= 0 ? measurement.data.data() +
                                           (v * rows + static_cast<std::size_t>(above)) * columns
                                     : nullptr;
      for (std::size_t c = 0; c < columns; ++c) {
        const bool has_low = low && std::isfinite(low[c]),
                   has_high = high && std::isfinite(high[c]);
        if (has_low && has_high) {
          line[c] = (1.0f - w) * low[c] + w * high[c];
        } else if (has_low) {
          line[c] = low[c];
        } else if (has_high) {
          line[c] = high[c];
        }
      }
    }
  }
  return filled;
}

}  // namespace riner::model
