// A trained result saved for replaying the ring corrections on it (the ring_chain_replay case):
// the field, the trained alpha, the dead elements, the geometry, the reference (a simulated
// scan's ground truth, or a real scan's FBP) and which pixels the reconstruction zeroed as
// skipped air. Written by any case that trains (ring_chain_replay --save, size_scaling --save).
// A replay runs the chain only: the readings' detail and the gradient step after it need the
// scan, so a replayed image is the run's image before the detail.
#pragma once

#include <filesystem>
#include <vector>

#include "riner/array.hpp"
#include "riner/geometry.hpp"
#include "riner/reconstructor.hpp"
#include "riner/riner_config.hpp"

namespace riner::bench {

struct SavedTraining {
  Geometry geometry;
  Array field, alpha, reference, keep;
  std::vector<std::size_t> dead;
  bool simulated = false;  // reference: ground truth (else the scan's FBP)
};

// r: after run(). rings: the chain the run used (to find the pixels it zeroed afterwards).
void save_training(const std::filesystem::path& dir, Reconstructor& r, const Geometry& g,
                   const Array& reference, bool simulated, const RingCorrectionConfig& rings);
SavedTraining load_training(const std::filesystem::path& dir);

}  // namespace riner::bench
