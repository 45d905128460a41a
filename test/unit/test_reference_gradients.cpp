// The reference step's gradient against central finite differences of its own loss, in double:
// every parameter group (grid, MLP, alpha0, beta0), with the ring prior and coarse-to-fine
// level scales on; alpha0 and beta0 per element, and per segment of views where every third
// element's response changes half-way (training.partial_responses); every third reading a
// bound (+inf).
#include <doctest/doctest.h>

#include <algorithm>
#include <random>

#include "model/batch_sampler.hpp"
#include "reference/alpha_factors_ref.hpp"
#include "reference/riner_step_ref.hpp"
#include "support/fixture.hpp"
#include "support/tiny_problem.hpp"

TEST_SUITE("reference_gradients") {
  TEST_CASE("step gradient matches central differences to 1e-5 relative") {
    for (bool changing : {false, true}) {
      CAPTURE(changing);
      const riner::test::TinyProblem t = riner::test::tiny_problem(3);
      std::vector<riner::model::ResponseChange> changes;
      for (std::size_t e = 1; changing && e < t.geometry.n_u; e += 3) {
        changes.push_back({e, {t.geometry.n_views() / 2}, false});
      }
      const riner::model::ResponseMap map(t.geometry.n_u, t.geometry.n_views(), changes);
      const auto layout = riner::model::make_layout(2, {3, 2, 6, 4, 16}, {16, 2}, map.slots());
      const riner::model::RaySegments segments(t.geometry, 1.0, false);
      std::vector<double> params;
      for (float v : riner::model::initial_parameters(layout, 5)) params.push_back(v);
      // (A draw away from the L1 and ReLU kinks for both maps.)
      std::mt19937 rng(static_cast<unsigned>(riner::test::seed() + (changing ? 1 : 0)));
      std::uniform_real_distribution<double> u(-0.5, 0.5);
      // Grid values away from 0 so ReLUs and features are in general position; responses spread.
      for (std::size_t i = 0; i < layout.grid_params; ++i) params[i] = u(rng);
      for (std::size_t e = 0; e < layout.elements; ++e) {
        params[layout.alpha_offset + e] = 1.0 + 0.4 * u(rng);
        params[layout.beta_offset + e] = 1.0 + u(rng);
      }
      riner::TrainingConfig tc;
      tc.sampler = riner::Sampler::kMixed;
      tc.rays_per_step = 12;
      tc.views_per_step = 4;
      tc.elements_per_step = 5;
      const riner::model::BatchSampler sampler(t.geometry, tc);
      const riner::model::Batch batch = sampler.batch(0);
      // Every third reading a bound (+inf: a beam the object stopped) at the readings' 40th
      // percentile, which some of the batch's rays meet and some do not.
      std::vector<float> rho = t.scan.measurement.data;
      std::vector<float> sorted = rho;
      std::sort(sorted.begin(), sorted.end());
      for (std::size_t ray = 1; ray < rho.size(); ray += 3) rho[ray] = INFINITY;
      std::size_t bounds = 0;
      for (std::uint32_t ray : batch.rays) bounds += rho[ray] == INFINITY;
      CHECK(bounds > 0);
      riner::ref::StepInputs in;
      in.layout = &layout;
      in.segments = &segments;
      in.measurement = &rho;
      in.starved_floor = sorted[sorted.size() * 4 / 10];
      in.elements_per_view = t.geometry.n_u;
      in.jitter = true;  // fixed per step: the loss is still a function of the parameters
      in.seed = 9;
      in.lambda = 0.01;
      in.ring_lambda = 3.0;
      in.level_weights = {1.0f, 0.7f, 0.25f};
      in.responses = changing ? &map : nullptr;
      const riner::ref::StepResult r = riner::ref::riner_step(in, batch, params);
      auto loss = [&](const std::vector<double>& p) {
        const riner::ref::StepResult s = riner::ref::riner_step(in, batch, p, false);
        return s.data_loss + s.penalty;
      };
      double worst = 0.0;
      std::size_t worst_index = 0;
      int checked = 0;
      for (std::size_t i = 0; i < layout.total; ++i) {
        // Every touched parameter and every 5th untouched one (whose gradient must be 0).
        if (r.grad[i] == 0.0 && i % 5 != 0) continue;
        const double h = 1e-6 * std::max(1.0, std::fabs(params[i]));
        std::vector<double> plus = params;
        std::vector<double> minus = params;
        plus[i] += h;
        minus[i] -= h;
        const double fd = (loss(plus) - loss(minus)) / (2.0 * h);
        // Rounding leaves the difference ~1.5e-9 of noise (a loss of ~10 at h = 1e-6): below
        // gradients of 3e-4 the error is measured against that.
        const double err =
            std::fabs(fd - r.grad[i]) / std::max(3e-4, std::fabs(fd) + std::fabs(r.grad[i]));
        if (err > worst) {
          worst = err;
          worst_index = i;
        }
        ++checked;
      }
      MESSAGE("checked " << checked << " parameters; worst relative error " << worst << " at "
                         << worst_index << " (alpha0 from " << layout.alpha_offset
                         << ", beta0 from " << layout.beta_offset << ")");
      CHECK(checked > 300);
      CHECK(worst < 1e-5);
      if (changing) {
        std::size_t segments_read = 0;
        for (std::size_t slot = t.geometry.n_u; slot < map.slots(); ++slot)
          segments_read += r.grad[layout.alpha_offset + slot] != 0.0;
        CHECK(segments_read > 0);
      }
    }
  }

  TEST_CASE("alpha's row and column factors: their gradient matches central differences") {
    // The tiny scan's 50 elements taken as 5 rows x 10 columns: the chain rule through the
    // product does not depend on where the elements sit.
    const riner::test::TinyProblem t = riner::test::tiny_problem(4);
    const auto layout = riner::model::make_layout(2, {3, 2, 6, 4, 16}, {16, 1}, t.geometry.n_u, 5);
    REQUIRE(layout.factor_columns == 10);
    const riner::model::RaySegments segments(t.geometry, 1.0, false);
    std::vector<double> params;
    for (float v : riner::model::initial_parameters(layout, 6)) params.push_back(v);
    std::mt19937 rng(static_cast<unsigned>(riner::test::seed()) + 3);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    for (std::size_t i = 0; i < layout.grid_params; ++i) params[i] = u(rng);
    for (std::size_t f = layout.factor_offset; f < layout.beta_offset; ++f) {
      params[f] = 1.0 + 0.3 * u(rng);
    }
    riner::ref::alpha_factors_expand(layout, params);
    riner::TrainingConfig tc;
    tc.rays_per_step = 40;
    const riner::model::Batch batch = riner::model::BatchSampler(t.geometry, tc).batch(0);
    riner::ref::StepInputs in;
    in.layout = &layout;
    in.segments = &segments;
    in.measurement = &t.scan.measurement.data;
    in.elements_per_view = t.geometry.n_u;
    in.lambda = 0.01;
    in.level_weights = {1.0f, 1.0f, 1.0f};
    riner::ref::StepResult r = riner::ref::riner_step(in, batch, params);
    riner::ref::alpha_factors_gradient(layout, params, r.grad);
    auto loss = [&](std::vector<double> p) {
      riner::ref::alpha_factors_expand(layout, p);
      const riner::ref::StepResult s = riner::ref::riner_step(in, batch, p, false);
      return s.data_loss + s.penalty;
    };
    double worst = 0.0;
    int nonzero = 0;
    for (std::size_t i = layout.factor_offset; i < layout.beta_offset; ++i) {
      const double h = 1e-6;
      std::vector<double> plus = params;
      std::vector<double> minus = params;
      plus[i] += h;
      minus[i] -= h;
      const double fd = (loss(plus) - loss(minus)) / (2.0 * h);
      worst = std::max(
          worst, std::fabs(fd - r.grad[i]) / std::max(1e-4, std::fabs(fd) + std::fabs(r.grad[i])));
      nonzero += r.grad[i] != 0.0;
    }
    MESSAGE("worst relative error over the 15 factors " << worst);
    CHECK(nonzero == 15);  // 40 rays reach every row and column
    CHECK(worst < 1e-5);
  }
}
