// The learning-rate schedule (TrainingSetup::learning_rate): smooth by default, lr_decay per
// interval reached continuously; in steps when asked and in the paper's configuration; the
// intervals still mark the phases (beta's warm-up).
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

  TEST_CASE("the paper's configuration halves in steps every 1000") {
    const riner::RinerConfig paper = riner::RinerConfig::paper();
    CHECK_FALSE(paper.training.lr_decay_smooth);
    const riner::detail::TrainingSetup setup(riner::test::tiny_problem().scan, paper);
    CHECK(setup.learning_rate(1500) == doctest::Approx(5e-4));
  }
}
