#include "model/stuck_elements.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace riner::model {

namespace {

constexpr double kSteadyFraction = 0.05;
constexpr double kJudgedNoiseSigmas = 10.0;
constexpr long kFarthestNeighbour = 2;
// A band of steady columns (a dead detector module) up to this share of the detector's width.
constexpr double kWidestBandShare = 0.25;

}  // namespace

std::vector<std::uint8_t> stuck_elements(const Scan& scan, double noise_sigma) {
  const Geometry& g = scan.geometry;
  const std::size_t views = g.n_views();
  const long columns = static_cast<long>(g.n_u);
  const long rows = g.is_3d() ? static_cast<long>(g.n_v) : 1;
  const std::size_t per_view = static_cast<std::size_t>(rows * columns);
  std::vector<std::uint8_t> stuck(per_view, 0);
  if (views < 2) return stuck;
  // Variance over the views; NaN where any reading is not finite.
  std::vector<double> sum(per_view, 0.0), squares(per_view, 0.0);
  const std::vector<float>& rho = scan.measurement.data;
  for (std::size_t v = 0; v < views; ++v) {
    for (std::size_t e = 0; e < per_view; ++e) {
      const double x = rho[v * per_view + e];
      sum[e] += x;  // a non-finite reading makes the sum non-finite
      squares[e] += x * x;
    }
  }
  std::vector<double> variance(per_view);
  const double n = static_cast<double>(views);
  for (std::size_t e = 0; e < per_view; ++e) {
    const double mean = sum[e] / n;
    variance[e] = std::isfinite(mean) ? std::max(0.0, squares[e] / n - mean * mean)
                                      : std::numeric_limits<double>::quiet_NaN();
  }
  const double judged = kJudgedNoiseSigmas * kJudgedNoiseSigmas * noise_sigma * noise_sigma;
  auto at = [&](long r, long c) {
    if (r < 0 || r >= rows || c < 0 || c >= columns)
      return std::numeric_limits<double>::quiet_NaN();
    return variance[static_cast<std::size_t>(r * columns + c)];
  };
  const auto varies = [&](long r, long c) {
    const double v = at(r, c);
    return std::isfinite(v) && v > judged;
  };
  // Matter at (r, c), seen from its steady neighbour (outward is (dr, dc)): an element that
  // varies beside a steady one or a band is matter's where an element beside it varies too
  // (outward, or across: a silhouette's rim runs along the detector); a failing element in the
  // air stands alone. Elements 8 and 32 of a simulated fan scan, changing part-way, made the 23
  // air columns between them a "dead module"; elements 494 and 498 made air element 496 stuck.
  const auto matter_at = [&](long r, long c, long dr, long dc) {
    return varies(r, c) &&
           (varies(r + dr, c + dc) || varies(r + dc, c + dr) || varies(r - dc, c - dr));
  };
  for (long r = 0; r < rows; ++r) {
    for (long c = 0; c < columns; ++c) {
      const double own = at(r, c);
      if (!std::isfinite(own)) continue;
      bool found = false;
      for (long d = 1; d <= kFarthestNeighbour && !found; ++d) {
        for (const auto& [dr, dc] : {std::pair{0L, 1L}, std::pair{1L, 0L}}) {
          // Both neighbours there and varying (matter_at), the element steady against them.
          if (matter_at(r - d * dr, c - d * dc, -dr, -dc) &&
              matter_at(r + d * dr, c + d * dc, dr, dc) &&
              own < kSteadyFraction *
                        std::fmin(at(r - d * dr, c - d * dc), at(r + d * dr, c + d * dc))) {
            found = true;
          }
        }
      }
      stuck[static_cast<std::size_t>(r * columns + c)] = found;
    }
  }
  // Wider bands along a row (a dead module of 20 columns): columns steady against the varying
  // columns either side of the band. Real matter cannot make one: a column reads lines at one
  // distance from the axis in every direction, so an off-centre part that makes the columns
  // beyond the band vary crosses the band's lines too; columns steady over the views lie beyond
  // every such part, out to the detector's end, where a band has no second side. Each side is
  // matter's.
  const long widest =
      std::max(3L, static_cast<long>(kWidestBandShare * static_cast<double>(columns)));
  for (long r = 0; r < rows; ++r) {
    long c = 0;
    while (c < columns) {
      if (varies(r, c)) {
        ++c;
        continue;
      }
      long end = c;  // the band [c, end)
      while (end < columns && !varies(r, end)) ++end;
      if (end - c <= widest && matter_at(r, c - 1, 0, -1) && matter_at(r, end, 0, 1)) {
        const double bound = std::fmin(at(r, c - 1), at(r, end));
        bool steady = true;
        for (long k = c; k < end && steady; ++k) {
          const double own = at(r, k);
          steady = !std::isfinite(own) || own < kSteadyFraction * bound;
        }
        for (long k = c; k < end && steady; ++k) {
          if (std::isfinite(at(r, k))) stuck[static_cast<std::size_t>(r * columns + k)] = 1;
        }
      }
      c = end;
    }
  }
  return stuck;
}

}  // namespace riner::model
