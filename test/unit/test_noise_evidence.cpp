// The noise evidence that turns coarse-to-fine training on (model/noise_evidence.hpp): known
// Gaussian noise on a smooth sinogram reads back; per-element offsets do not count as noise;
// level_warmup_steps -1 becomes steps / 24 on a noisy scan and 0 on a quiet one, and
// tail_average_steps -1 the last learning-rate phase on a noisy scan and 0 on a quiet one.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "model/noise_evidence.hpp"
#include "training/trainer.hpp"

namespace {

// 180 views of a disc off the axis (peak 2) across 64 elements, with an offset on every
// seventh element and Gaussian noise of `sigma`.
riner::Scan disc_scan(double sigma) {
  riner::Scan scan;
  riner::Geometry& g = scan.geometry;
  g.type = riner::GeometryType::kParallel2d;
  g.n_u = 64;
  g.volume_shape = {48, 48};
  for (int v = 0; v < 180; ++v) g.angles.push_back(M_PI * v / 180.0);
  scan.measurement = riner::Array({180, 64});
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, sigma);
  for (std::size_t v = 0; v < 180; ++v) {
    const double centre = 8.0 * std::cos(g.angles[v]);
    for (std::size_t u = 0; u < 64; ++u) {
      const double x = (static_cast<double>(u) - 31.5 - centre) / 12.0;
      const double chord = std::fabs(x) < 1.0 ? 2.0 * std::sqrt(1.0 - x * x) : 0.0;
      scan.measurement(v, u) = static_cast<float>(chord + (u % 7 == 3 ? 0.05 : 0.0) + noise(rng));
    }
  }
  return scan;
}

}  // namespace

TEST_SUITE("noise evidence") {
  TEST_CASE("Gaussian noise on a smooth sinogram reads back within 10%") {
    for (double sigma : {0.003, 0.02}) {
      CAPTURE(sigma);
      const riner::model::NoiseEvidence e = riner::model::reading_noise(disc_scan(sigma));
      CHECK(e.sigma == doctest::Approx(sigma).epsilon(0.1));
      CHECK(e.level == doctest::Approx(2.0).epsilon(0.05));
      CHECK(e.relative == doctest::Approx(e.sigma / e.level));
    }
    // Noise-free: the object's turning and the offsets leave far less than the quieter case.
    CHECK(riner::model::reading_noise(disc_scan(0.0)).sigma < 0.001);
  }

  TEST_CASE("non-finite readings are skipped; too few views give zeros") {
    riner::Scan scan = disc_scan(0.01);
    for (std::size_t u = 0; u < 64; u += 5) scan.measurement(90, u) = NAN;
    CHECK(riner::model::reading_noise(scan).sigma == doctest::Approx(0.01).epsilon(0.1));
    scan.geometry.angles.resize(2);
    scan.measurement = riner::Array({2, 64}, 1.0f);
    CHECK(riner::model::reading_noise(scan).relative == 0.0);
  }

  TEST_CASE("level_warmup_steps -1: steps / 24 on a noisy scan, 0 on a quiet one") {
    riner::RinerConfig config;
    config.training.steps = 1200;
    // 0.02 / 2 = 1e-2 >= 0.001; 0.001 / 2 = 5e-4 below.
    CHECK(
        riner::detail::TrainingSetup(disc_scan(0.02), config).config.training.level_warmup_steps ==
        50);
    CHECK(
        riner::detail::TrainingSetup(disc_scan(0.001), config).config.training.level_warmup_steps ==
        0);
    config.training.level_warmup_steps = 7;  // an explicit value stays
    CHECK(
        riner::detail::TrainingSetup(disc_scan(0.02), config).config.training.level_warmup_steps ==
        7);
    config.training.level_warmup_steps = -1;
    config.training.steps = -1;  // the scan's: 24 000 for a slice
    const riner::detail::TrainingSetup slice(disc_scan(0.02), config);
    CHECK(slice.config.training.steps == 24000);
    CHECK(slice.config.training.level_warmup_steps == 1000);
  }

  TEST_CASE(
      "tail_average_steps -1: the last learning-rate phase on a noisy scan, 0 on a quiet one") {
    riner::RinerConfig config;
    config.training.steps = 1200;
    const riner::detail::TrainingSetup noisy(disc_scan(0.02), config);
    CHECK(noisy.config.training.tail_average_steps == 300);
    CHECK(noisy.tail_average.steps == 300);
    CHECK(noisy.tail_average.total == 1200);
    CHECK(riner::detail::TrainingSetup(disc_scan(0.001), config).tail_average.steps == 0);
    config.training.lr_decay_steps = 200;  // a shorter last phase
    CHECK(riner::detail::TrainingSetup(disc_scan(0.02), config).tail_average.steps == 200);
    config.training.lr_decay_steps = 5000;  // one phase only: still the last quarter at most
    CHECK(riner::detail::TrainingSetup(disc_scan(0.02), config).tail_average.steps == 300);
    config.training.tail_average_steps = 40;  // an explicit value stays, on a quiet scan too
    CHECK(riner::detail::TrainingSetup(disc_scan(0.001), config).tail_average.steps == 40);
    config.training.tail_average_steps = 5000;  // longer than the run: the whole run
    CHECK(riner::detail::TrainingSetup(disc_scan(0.001), config).tail_average.steps == 1200);
    config = riner::RinerConfig::paper();
    CHECK(riner::detail::TrainingSetup(disc_scan(0.02), config).tail_average.steps == 0);
  }
}
