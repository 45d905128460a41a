// Training pushed to extremes: a huge learning rate, beta driven to 0 or 1, alpha driven to 0,
// ten times the steps. Either finite results or a clear divergence error, never NaN output.
#include <doctest/doctest.h>

#include <cmath>

#include "riner/error.hpp"
#include "riner/reconstructor.hpp"
#include "support/fixture.hpp"
#include "support/tiny_problem.hpp"

namespace {

bool all_finite(const riner::Array& a) {
  for (float v : a.data) {
    if (!std::isfinite(v)) return false;
  }
  return true;
}

}  // namespace

TEST_SUITE("extreme_training") {
  TEST_CASE("learning rate x100: finite results or a divergence error naming the step") {
    const riner::test::TinyProblem t = riner::test::tiny_problem(21);
    riner::RinerConfig c = riner::test::tiny_config();
    c.training.learning_rate *= 100.0;
    riner::Reconstructor r(t.scan, c, riner::test::device());
    try {
      r.run();
      CHECK(all_finite(r.image()));
      CHECK(all_finite(r.alpha()));
      CHECK(all_finite(r.beta()));
    } catch (const riner::Error& e) {
      CHECK(std::string(e.what()).find("training diverged at step") != std::string::npos);
    }
  }

  TEST_CASE("beta driven to 0 (no penalty) and to 1 (a huge penalty)") {
    const riner::test::TinyProblem t = riner::test::tiny_problem(22);
    for (double lambda : {0.0, 1e4}) {
      CAPTURE(lambda);
      riner::RinerConfig c = riner::test::tiny_config();
      c.training.lambda = lambda;
      c.training.relative_beta_threshold = 0.0;  // lambda alone: 0 is no penalty at all
      c.training.beta_lr_scale = 30.0;
      riner::Reconstructor r(t.scan, c, riner::test::device());
      r.run();
      CHECK(all_finite(r.image()));
      const riner::Array beta = r.trained_beta();
      CHECK(all_finite(beta));
      // Over the elements that read something: the dead one reads nothing, starts with its
      // beta near 0 and stays there, where the penalty's pull (-2 lambda beta^2 (1 - beta))
      // vanishes.
      double mean = 0.0;
      std::size_t reading = 0;
      for (std::size_t e = 0; e < beta.size(); ++e) {
        if (t.alpha.data[e] == 0.0f) continue;
        mean += beta.data[e];
        ++reading;
      }
      mean /= static_cast<double>(reading);
      CHECK(reading + 1 == beta.size());
      if (lambda == 0.0) CHECK(mean < 0.3);  // the trivial solution the penalty exists to stop
      if (lambda > 0.0) CHECK(mean > 0.99);
    }
  }

  TEST_CASE("alpha driven to its clamp at 1e-8") {
    // Every reading 19 above its line integral (alpha 6e-9, under the clamp; a scan whose
    // least readings pass 20 is refused as raw intensities): -ln alpha must grow, alpha0 goes
    // through 0.
    riner::test::TinyProblem t = riner::test::tiny_problem(23, 0);
    for (float& v : t.scan.measurement.data) v += 19.0f;
    riner::RinerConfig c = riner::test::tiny_config();
    c.training.alpha_lr_scale = 300.0;
    riner::Reconstructor r(t.scan, c, riner::test::device());
    r.run();
    CHECK(all_finite(r.image()));
    const riner::Array alpha = r.alpha();
    CHECK(all_finite(alpha));
    for (float a : alpha.data) CHECK(a >= 1e-8f);
  }

  TEST_CASE("ten times the steps stays finite and keeps improving the fit") {
    const riner::test::TinyProblem t = riner::test::tiny_problem(24);
    riner::RinerConfig c = riner::test::tiny_config();
    c.training.steps = 3000;
    riner::Reconstructor r(t.scan, c, riner::test::device());
    r.run();
    CHECK(all_finite(r.image()));
    const auto h = r.history();
    double first = 0.0, last = 0.0;
    for (int i = 0; i < 100; ++i) {
      first += h[static_cast<std::size_t>(i)].data_loss;
      last += h[h.size() - 1 - static_cast<std::size_t>(i)].data_loss;
    }
    CHECK(last < first);
  }
}
