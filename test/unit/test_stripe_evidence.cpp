// The stripe evidence that sets alpha's learning rate (model/stripe_evidence.hpp): known
// offsets on a smooth object read back; the object alone reads far less; elements with
// non-finite readings are left out; the rate follows min(1, stripe / alpha_stripe_scale).
#include <doctest/doctest.h>

#include <cmath>

#include "model/stripe_evidence.hpp"
#include "training/trainer.hpp"

namespace {

// 40 views of a broad bump (peak 0.5) across 100 elements, plus `offset` on every tenth element.
riner::Scan bump_scan(float offset) {
  riner::Scan scan;
  scan.geometry.type = riner::GeometryType::kParallel2d;
  scan.geometry.n_u = 100;
  for (int v = 0; v < 40; ++v) scan.geometry.angles.push_back(M_PI * v / 40.0);
  scan.geometry.volume_shape = {64, 64};
  scan.measurement = riner::Array({40, 100});
  for (std::size_t v = 0; v < 40; ++v) {
    for (std::size_t u = 0; u < 100; ++u) {
      const double x = (static_cast<double>(u) - 50.0) / 80.0;
      scan.measurement(v, u) = static_cast<float>(0.5 * std::exp(-x * x)) +
                               (u % 10 == 5 ? offset : 0.0f);
    }
  }
  return scan;
}

}  // namespace

TEST_SUITE("stripe evidence") {
  TEST_CASE("offsets on every tenth element read back as their RMS") {
    const double rms = riner::model::stripe_rms(bump_scan(0.05f));
    // Ten offsets among the 94 elements whose window is centred; the bump's slope (up to
    // 0.005 per element) takes a little off each.
    CHECK(rms == doctest::Approx(0.05 * std::sqrt(10.0 / 94.0)).epsilon(0.1).scale(0));
    // The bump alone reads under a tenth of that.
    CHECK(riner::model::stripe_rms(bump_scan(0.0f)) < 0.1 * rms);
  }

  TEST_CASE("an element with a non-finite reading is left out") {
    riner::Scan scan = bump_scan(0.05f);
    for (std::size_t u = 5; u < 100; u += 10) scan.measurement(3, u) = NAN;  // dead offsets
    CHECK(riner::model::stripe_rms(scan) < 0.1 * 0.05 * std::sqrt(10.0 / 94.0));
  }

  TEST_CASE("alpha's rate: alpha_lr_scale x min(1, stripe / alpha_stripe_scale)") {
    riner::RinerConfig config;
    config.training.alpha_lr_scale = 0.5;
    const riner::detail::TrainingSetup weak(bump_scan(0.01f), config);
    CHECK(weak.stripe_rms < 0.05);
    CHECK(weak.alpha_rate == doctest::Approx(0.5 * weak.stripe_rms / 0.05).scale(0));
    const riner::detail::TrainingSetup strong(bump_scan(0.5f), config);
    CHECK(strong.alpha_rate == doctest::Approx(0.5));
    config.training.alpha_stripe_scale = 0.0;  // off
    const riner::detail::TrainingSetup off(bump_scan(0.01f), config);
    CHECK(off.alpha_rate == doctest::Approx(0.5));
    CHECK(off.adam_settings(0).alpha_learning_rate ==
          doctest::Approx(0.5 * config.training.learning_rate));
  }
}
