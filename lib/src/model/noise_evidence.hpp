// How noisy the readings are against their size, read off the measurement before training:
// the noise sigma from each element's second differences along the views (the object turns
// smoothly from view to view; the detector's offsets cancel), over the 99th percentile of the
// readings. The paper's simulated scans (10^7 photons) read ~6e-5; the shared real neutron
// and X-ray scans 2e-3 to 7e-3 (docs/history/RESULTS.md, issue 13), where the finest encoding
// levels fit noise unless the coarse ones form first (training.level_warmup_steps -1).
#pragma once

#include "riner/scan.hpp"

namespace riner::model {

struct NoiseEvidence {
  double sigma = 0.0;     // the readings' noise, rho units
  double level = 0.0;     // 99th percentile of the readings
  double relative = 0.0;  // sigma / level; 0 when either is unknown
};

// Zeros when fewer than three views or no finite triple of readings.
NoiseEvidence reading_noise(const Scan& scan);

}  // namespace riner::model
