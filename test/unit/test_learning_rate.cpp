// The learning-rate schedule (TrainingSetup::learning_rate): smooth by default, lr_decay per
// interval reached continuously; in steps when asked, in the paper's configuration and on a scan
// whose rays each cross more sampled voxels than smooth_decay_max_voxels_per_ray; the intervals
// still mark the phases (beta's warm-up).
#include <doctest/doctest.h>

#include <cmath>

#include "support/tiny_problem.hpp"
#include "training/trainer.hpp"

TEST_SUITE("learning rate") {
  TEST_CASE("smooth: lr_decay per interval, reached continuously") {
    riner::RinerConfig config;
    config.training.steps = 4000;  // interval 1000
    const riner::detail::TrainingSetup setup(riner::test::tiny_problem().scan, config);
    CHECK(setup.learning_rate(0) == doctest::Approx(1e-3));
    CHECK(setup.learning_rate(500) == doctest::Approx(1e-3 * std::sqrt(0.5)));
    CHECK(setup.learning_rate(1000) == doctest::Approx(5e-4));
    CHECK(setup.learning_rate(3999) == doctest::Approx(1e-3 * std::pow(0.5, 3.999)));
    CHECK(setup.config.training.beta_warmup() == 1000);  // the phases are the intervals
  }

  TEST_CASE("in steps: constant within an interval, lr_decay at each") {
    riner::RinerConfig config;
    config.training.steps = 4000;
    config.training.lr_decay_smooth = false;
    const riner::detail::TrainingSetup setup(riner::test::tiny_problem().scan, config);
    CHECK(setup.learning_rate(999) == doctest::Approx(1e-3));
    CHECK(setup.learning_rate(1000) == doctest::Approx(5e-4));
    CHECK(setup.learning_rate(3999) == doctest::Approx(1.25e-4));
  }

  TEST_CASE("a scan with fewer readings than unknowns decays in steps") {
    riner::RinerConfig config;
    config.training.steps = 4000;
    // 90 views of 50 elements over the 48 x 48 grid: 0.4 sampled voxels per ray, smooth.
    const riner::detail::TrainingSetup many(riner::test::tiny_problem().scan, config);
    CHECK(many.voxels_per_ray > 0.2);
    CHECK(many.voxels_per_ray < 0.6);
    CHECK(many.config.training.lr_decay_smooth);
    // 12 views: 3 voxels per ray, in steps.
    const riner::Scan few_views = riner::test::tiny_problem(1, 1, M_PI, 12).scan;
    const riner::detail::TrainingSetup few(few_views, config);
    CHECK(few.voxels_per_ray > 2.0);
    CHECK(few.voxels_per_ray < 4.0);
    CHECK_FALSE(few.config.training.lr_decay_smooth);
    CHECK(few.learning_rate(999) == doctest::Approx(1e-3));
    CHECK(few.learning_rate(1000) == doctest::Approx(5e-4));
    // 0: smooth on every scan.
    config.training.smooth_decay_max_voxels_per_ray = 0.0;
    const riner::detail::TrainingSetup asked(few_views, config);
    CHECK(asked.config.training.lr_decay_smooth);
    CHECK(asked.learning_rate(500) == doctest::Approx(1e-3 * std::sqrt(0.5)));
  }

  TEST_CASE("the paper's configuration halves in steps every 1000") {
    const riner::RinerConfig paper = riner::RinerConfig::paper();
    CHECK_FALSE(paper.training.lr_decay_smooth);
    const riner::detail::TrainingSetup setup(riner::test::tiny_problem().scan, paper);
    CHECK(setup.learning_rate(1500) == doctest::Approx(5e-4));
  }
}
