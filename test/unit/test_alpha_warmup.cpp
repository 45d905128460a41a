// alpha's warm-up left to the scan (TrainingConfig::kScanAlphaWarmup): still for the first
// kWideAlphaWarmup steps on a slice whose detector row has at least kWideDetectorElements
// elements, from the first step on smaller ones and after a warm start; a value given is
// kept, and the paper's configuration starts at once.
#include <doctest/doctest.h>

#include <cmath>

#include "riner/phantom.hpp"
#include "riner/simulate.hpp"
#include "support/tiny_problem.hpp"
#include "training/trainer.hpp"

namespace {

riner::Scan parallel_scan(std::size_t elements) {
  riner::Geometry g;
  g.type = riner::GeometryType::kParallel2d;
  g.n_u = elements;
  g.pitch_u = 96.0 / static_cast<double>(elements);
  g.voxel_mm = 1.5;
  g.volume_shape = {64, 64};
  g.uniform_angles = riner::UniformAngles{6, 0.0, M_PI};
  g.angles = riner::uniform_angles(*g.uniform_angles);
  const riner::Phantom p = riner::shepp_logan(g, 0.1);
  return riner::Scan{riner::exact_projections(p, g), g, 0};
}

int resolved(const riner::Scan& scan, const riner::RinerConfig& config) {
  return riner::detail::TrainingSetup(scan, config).config.training.alpha_warmup_steps;
}

}  // namespace

TEST_SUITE("alpha warm-up") {
  TEST_CASE("left to the scan: 300 steps from 1000 elements a row, none below") {
    const riner::RinerConfig config;
    REQUIRE(config.training.alpha_warmup_steps == riner::TrainingConfig::kScanAlphaWarmup);
    CHECK(resolved(parallel_scan(1000), config) == riner::TrainingConfig::kWideAlphaWarmup);
    CHECK(resolved(parallel_scan(999), config) == 0);
    CHECK(resolved(riner::test::tiny_problem().scan, config) == 0);
  }

  TEST_CASE("a value given is kept; the paper's alpha learns from the first step") {
    riner::RinerConfig config;
    config.training.alpha_warmup_steps = 7;
    CHECK(resolved(parallel_scan(1000), config) == 7);
    CHECK(resolved(parallel_scan(1000), riner::RinerConfig::paper()) == 0);
  }

  TEST_CASE("a warm start's alpha is not held: it starts from the classical correction") {
    riner::RinerConfig config;
    config.training.warm_start = "wavelet";
    CHECK(resolved(parallel_scan(1000), config) == 0);
  }

  TEST_CASE("the setting takes -1 and refuses below it") {
    riner::RinerConfig config;
    config.training.alpha_warmup_steps = -2;
    CHECK_THROWS(config.validate());
  }
}
