// kernels/alpha_factors.cl against its CPU twin: the factors' gradient from random per-element
// gradients, and the product back into alpha0, on detectors of several shapes.
#include <doctest/doctest.h>

#include <random>

#include "cl/buffer.hpp"
#include "cl/device_access.hpp"
#include "model/parameter_layout.hpp"
#include "ops/alpha_factors.hpp"
#include "reference/alpha_factors_ref.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"
#include "support/tolerances.hpp"

TEST_SUITE("alpha_factors") {
  TEST_CASE("the factors' gradient and the product match the reference") {
    riner::cl::Context& ctx = riner::cl::context_of(riner::test::device());
    std::mt19937 rng(static_cast<unsigned>(riner::test::seed()));
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const riner::EncodingConfig encoding{2, 2, 6, 4, 8};
    for (const auto& [rows, columns] : {std::pair{1, 1}, {1, 9}, {7, 1}, {13, 29}, {200, 300}}) {
      CAPTURE(rows);
      CAPTURE(columns);
      const auto l =
          riner::model::make_layout(3, encoding, {16, 1}, static_cast<std::size_t>(rows) * columns,
                                    static_cast<std::size_t>(rows));
      REQUIRE(l.factored_alpha());
      std::vector<double> params(l.total);
      std::vector<double> grad(l.total);
      for (std::size_t i = 0; i < l.total; ++i) {
        params[i] = 1.0 + 0.3 * u(rng);
        grad[i] = u(rng);
      }
      std::vector<float> params_f(params.begin(), params.end());
      std::vector<float> grad_f(grad.begin(), grad.end());
      // The float inputs are what both sides see.
      for (std::size_t i = 0; i < l.total; ++i) {
        params[i] = params_f[i];
        grad[i] = grad_f[i];
      }
      riner::cl::Buffer<float> d_params(ctx, std::span<const float>(params_f));
      riner::cl::Buffer<float> d_grad(ctx, std::span<const float>(grad_f));
      riner::ops::AlphaFactorsOp op(ctx, l);
      op.gradient(d_params, d_grad);
      riner::ref::alpha_factors_gradient(l, params, grad);
      // One pass of up to 300 float products summed per factor.
      const auto g = riner::test::compare(d_grad.read(), grad);
      CHECK_MESSAGE(g.rms_rel < riner::test::tolerance::kOnePass, g.describe());
      op.expand(d_params);
      riner::ref::alpha_factors_expand(l, params);
      const auto p = riner::test::compare(d_params.read(), params);
      CHECK_MESSAGE(p.max_rel < riner::test::tolerance::kElementwise, p.describe());
    }
  }

  TEST_CASE("a layout without factors is refused") {
    riner::cl::Context& ctx = riner::cl::context_of(riner::test::device());
    const auto l = riner::model::make_layout(3, {2, 2, 6, 4, 8}, {16, 1}, 12);
    CHECK_THROWS_WITH(riner::ops::AlphaFactorsOp(ctx, l),
                      doctest::Contains("the layout has no factors"));
  }
}
