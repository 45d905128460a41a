#include "model/factor_evidence.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "model/stripe_evidence.hpp"

namespace riner::model {

namespace {

struct Energies {
  double total = 0.0;     // of the pattern
  double residual = 0.0;  // left after its mean over the lines
  std::size_t pixels = 0;
};

double median_times_count(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
  return v[v.size() / 2] * static_cast<double>(v.size());
}

// mean[line][position] (transposed: mean[position][line]); NaN where a pixel had a
// non-finite reading (element_means), which drops it out of the patterns. The pattern at (line, p)
// is mean(p) - (mean(p - 1) + mean(p + 1)) / 2.
Energies pattern_energies(const std::vector<double>& mean, std::size_t lines, std::size_t positions,
                          bool transposed) {
  auto at = [&](std::size_t line, std::size_t p) {
    return transposed ? mean[p * lines + line] : mean[line * positions + p];
  };
  Energies e;
  if (positions < 3) return e;
  std::vector<double> totals;
  std::vector<double> residuals;
  for (std::size_t p = 1; p + 1 < positions; ++p) {
    double sum = 0.0;
    double squares = 0.0;
    std::size_t n = 0;
    for (std::size_t line = 0; line < lines; ++line) {
      const double d = at(line, p) - 0.5 * (at(line, p - 1) + at(line, p + 1));
      if (!std::isfinite(d)) continue;
      sum += d;
      squares += d * d;
      ++n;
    }
    if (n == 0) continue;
    const double mean_over_lines = sum / static_cast<double>(n);
    totals.push_back(squares);
    residuals.push_back(squares - mean_over_lines * sum);
    e.pixels += n;
  }
  e.total = median_times_count(totals);
  e.residual = median_times_count(residuals);
  return e;
}

}  // namespace

FactorEvidence factor_evidence(const Scan& scan) {
  return factor_evidence(element_means(scan), scan.geometry);
}

FactorEvidence factor_evidence(const std::vector<double>& means, const Geometry& g) {
  FactorEvidence out;
  if (!g.is_3d()) return out;
  const std::size_t rows = g.n_v;
  const std::size_t columns = g.n_u;
  const Energies along_rows = pattern_energies(means, rows, columns, false);
  const Energies along_columns = pattern_energies(means, columns, rows, true);
  const double total = along_rows.total + along_columns.total;
  out.pixels = along_rows.pixels + along_columns.pixels;
  if (total > 0.0) {
    out.explained =
        std::clamp(1.0 - (along_rows.residual + along_columns.residual) / total, 0.0, 1.0);
  }
  return out;
}

}  // namespace riner::model
