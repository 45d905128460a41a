// A tiny ring scan that trains in seconds: a parallel-beam Shepp-Logan on a 48 x 48 grid with
// per-element responses and one dead element, plus a small model.
#pragma once

#include <cmath>

#include "riner/phantom.hpp"
#include "riner/riner_config.hpp"
#include "riner/simulate.hpp"

namespace riner::test {

struct TinyProblem {
  Geometry geometry;
  Array truth;
  Array alpha;
  Scan scan;
};

// range_rad: the views' span, 180 degrees unless a test needs a full turn; views: 90 unless a
// test needs a scan with fewer readings than unknowns.
inline TinyProblem tiny_problem(std::uint64_t seed = 1, std::size_t dead = 1,
                                double range_rad = M_PI, std::size_t views = 90) {
  TinyProblem t;
  Geometry& g = t.geometry;
  g.type = GeometryType::kParallel2d;
  g.n_u = 50;
  g.pitch_u = 1.0;
  g.voxel_mm = 1.0;
  g.volume_shape = {48, 48};
  g.uniform_angles = UniformAngles{views, 0.0, range_rad};
  g.angles = uniform_angles(*g.uniform_angles);
  const Phantom p = shepp_logan(g, 0.1);
  t.truth = rasterize(p, g, 4);
  RingModel model;
  model.seed = seed;
  model.dead_elements = dead;
  const Array clean = exact_projections(p, g);
  t.alpha = draw_responses(g, model);
  t.scan = Scan{corrupt_measurement(clean, t.alpha, model), g, 0};
  t.scan.non_finite = compute_stats(t.scan.measurement).non_finite();
  return t;
}

inline RinerConfig tiny_config() {
  RinerConfig c;
  c.encoding = {4, 2, 12, 6, 48};
  c.network = {16, 1};
  c.training.steps = 300;
  c.training.rays_per_step = 64;
  c.training.learning_rate = 3e-3;
  c.training.lr_decay_steps = 500;
  c.training.beta_warmup_steps = 0;  // scaled to these short runs, like the decay: none
  return c;
}

}  // namespace riner::test
