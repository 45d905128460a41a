// alpha's warm-up left to the scan (TrainingConfig::kScanAlphaWarmup): still for the first
// kWideAlphaWarmup steps on a slice whose detector row has at least kWideDetectorElements
// elements, from the first step on smaller ones and after a warm start; a value given is
// kept, and the paper's configuration starts at once. The hold of only alpha's broad part even
// about the axis (model/broad_even_hold.hpp).
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "model/broad_even_hold.hpp"
#include "riner/rays.hpp"

#include "riner/phantom.hpp"
#include "riner/simulate.hpp"
#include "support/tiny_problem.hpp"
#include "training/trainer.hpp"

namespace {

riner::Scan parallel_scan(std::size_t elements, double range_rad = M_PI) {
  riner::Geometry g;
  g.type = riner::GeometryType::kParallel2d;
  g.n_u = elements;
  g.pitch_u = 96.0 / static_cast<double>(elements);
  g.voxel_mm = 1.5;
  g.volume_shape = {64, 64};
  g.uniform_angles = riner::UniformAngles{6, 0.0, range_rad};
  g.angles = riner::uniform_angles(*g.uniform_angles);
  const riner::Phantom p = riner::shepp_logan(g, 0.1);
  return riner::Scan{riner::exact_projections(p, g), g, 0};
}

double rms(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x * x;
  return std::sqrt(s / static_cast<double>(v.size()));
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

  TEST_CASE("the broad even hold takes out a broad even bump, keeps the odd and the narrow") {
    const riner::Geometry g = parallel_scan(1000).geometry;  // 0.096 mm elements, 1.5 mm pixels
    const std::vector<double> d = riner::column_ray_distances(g);
    std::vector<double> bump(d.size()), slope(d.size()), narrow(d.size());
    for (std::size_t e = 0; e < d.size(); ++e) {
      bump[e] = 0.1 * std::exp(-0.5 * d[e] * d[e] / (20.0 * 20.0));
      slope[e] = 0.05 * d[e] / 48.0;
      narrow[e] = (e % 2 == 0 ? 0.02 : -0.02) * (e % 7 == 3 ? 3.0 : 1.0);
    }
    const riner::model::BroadEvenHold hold(g, 2.0, std::vector<float>(d.size(), 1.0f));
    // The odd slope has no even part; the narrow offsets have next to no broad part.
    CHECK(rms(hold.broad_even(slope)) < 1e-9);
    CHECK(rms(hold.broad_even(narrow)) < 0.05 * rms(narrow));
    // As during a warm-up of 300 steps in which nothing else moves alpha.
    std::vector<double> alpha(d.size());
    for (std::size_t e = 0; e < d.size(); ++e) alpha[e] = std::exp(bump[e] + slope[e] + narrow[e]);
    for (int step = 0; step < 300; ++step) hold.apply(std::span<double>(alpha));
    std::vector<double> bump_left(d.size());
    for (std::size_t e = 0; e < d.size(); ++e)
      bump_left[e] = std::log(alpha[e]) - slope[e] - narrow[e];
    CHECK(rms(bump_left) < 0.02 * rms(bump));
  }

  TEST_CASE("the broad even hold in the setup: while alpha_warmup_steps last, on a full turn") {
    riner::RinerConfig config;
    CHECK(config.training.alpha_warmup_broad_px == 3.0);
    config.training.alpha_warmup_steps = 10;
    // 180 degrees read each line once: all of alpha is held whatever alpha_warmup_broad_px.
    const riner::detail::TrainingSetup half_turn(parallel_scan(1000), config);
    CHECK(half_turn.holds_all_alpha(9));
    CHECK_FALSE(half_turn.holds_broad_even_alpha(0));
    CHECK_FALSE(half_turn.broad_even_hold(std::vector<float>(1000, 1.0f)).has_value());
    config.training.alpha_warmup_broad_px = 0.0;
    const riner::Scan scan = parallel_scan(1000, 2.0 * M_PI);
    const riner::detail::TrainingSetup all(scan, config);
    CHECK(all.holds_all_alpha(9));
    CHECK_FALSE(all.holds_all_alpha(10));
    CHECK_FALSE(all.broad_even_hold(std::vector<float>(1000, 1.0f)).has_value());
    CHECK(all.adam_settings(9).alpha_learning_rate == 0.0);
    config.training.alpha_warmup_broad_px = 2.0;
    const riner::detail::TrainingSetup broad(scan, config);
    CHECK_FALSE(broad.holds_all_alpha(0));
    CHECK(broad.holds_broad_even_alpha(9));
    CHECK_FALSE(broad.holds_broad_even_alpha(10));
    CHECK(broad.broad_even_hold(std::vector<float>(1000, 1.0f)).has_value());
    CHECK(broad.adam_settings(0).alpha_learning_rate > 0.0);
    config.training.alpha_warmup_broad_px = -1.0;
    CHECK_THROWS(config.validate());
  }
}
