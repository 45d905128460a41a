// A scan with partial rings (issue 32): a Shepp-Logan in a 180-degree parallel beam, 240 views
// x 128 elements on a 96 x 96 grid, the paper's responses and noise, `partial` elements changing
// and `dying` dying part-way (riner simulate --partial/--partial-dead).
#pragma once

#include <cmath>

#include "riner/phantom.hpp"
#include "riner/simulate.hpp"
#include "support/geometries.hpp"

namespace riner::test {

struct PartialScan {
  Scan scan;
  Array alpha;  // [views, elements] when partial or dying > 0
  Array ground_truth;
};

inline PartialScan partial_scan(std::size_t partial, std::size_t dying, std::uint64_t seed) {
  const Geometry g =
      make_geometry(GeometryType::kParallel2d, 240, 128, 1, {96, 96}, 1.0, 1.0, M_PI);
  const Phantom phantom = shepp_logan(g, 0.1);
  const Array clean = exact_projections(phantom, g);
  RingModel model;
  model.seed = seed;
  model.partial_elements = partial;
  model.partial_dead_elements = dying;
  PartialScan s;
  s.alpha = draw_responses(g, model);
  s.scan = Scan{corrupt_measurement(clean, s.alpha, model), g, 0};
  s.ground_truth = rasterize(phantom, g, 4);
  return s;
}

}  // namespace riner::test
