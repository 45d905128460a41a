// Whether a 3D detector's responses are row x column factors (training.alpha_model auto), read
// off the measurement before training. Each pixel's mean reading over the views, less the mean
// of its two neighbours along its row, is the stripe pattern rings come from (linear, so the
// detector's part adds to the object's); along its column, the pattern across rows. Column
// factors make the first the same in every row, row factors the second the same in every
// column, so the patterns' means over rows (over columns) explain them. The evidence is the
// share of the patterns' energy those means explain: ~1 for a factored detector, ~1/rows +
// 1/columns for independent pixels or noise. Energies are medians over positions (times their
// number), so a few rows where the object's top or bottom edge falls do not decide it, while
// pixels that stray from the factors in every row still do.
#pragma once

#include <cstddef>
#include <vector>

#include "riner/scan.hpp"

namespace riner::model {

struct FactorEvidence {
  double explained = 0.0;  // 0..1
  std::size_t pixels = 0;  // pixels it was measured on (0: not measurable)
};

// 3D only (a 2D detector is one row: zero pixels). means: model::element_means of the scan.
FactorEvidence factor_evidence(const Scan& scan);
FactorEvidence factor_evidence(const std::vector<double>& means, const Geometry& g);

}  // namespace riner::model
