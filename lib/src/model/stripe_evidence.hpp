// How large the detector's element-to-element offsets are, read off the measurement before
// training: each element's mean reading over the views, less the median of the seven elements
// centred on it along the row (what the object leaves is smooth across elements once averaged
// over views; a ring-causing offset is not), as an RMS over the elements whose readings are
// all finite. On the paper's simulated detectors (alpha ~ U[0.75, 1.25]) it reads ~0.12; on
// the shared real scans 0.0015-0.0043 (docs/history/RESULTS.md, issue 13).
#pragma once

#include <cstddef>
#include <vector>

#include "riner/scan.hpp"

namespace riner::model {

// Each detector element's mean reading over the views ([rows][n_u] in 3D); NaN where any of
// its readings is not finite. The one pass over the measurement this and
// model/factor_evidence.hpp share.
std::vector<double> element_means(const Scan& scan);

// 0 when no row has seven elements with finite readings. means: element_means, rows of n_u.
double stripe_rms(const std::vector<double>& means, std::size_t n_u);
double stripe_rms(const Scan& scan);

}  // namespace riner::model
