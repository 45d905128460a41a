// Float32 ray sums over long rays (up to 4096 samples) against double: the error stays small.
#include <doctest/doctest.h>

#include <random>

#include "cl/buffer.hpp"
#include "cl/device_access.hpp"
#include "ops/ray_sum.hpp"
#include "reference/ray_sum_ref.hpp"
#include "support/fixture.hpp"

TEST_SUITE("ray_sum_precision") {
  TEST_CASE("sums of up to 4096 samples stay within 1e-5 relative of double") {
    riner::cl::Context& ctx = riner::cl::context_of(riner::test::device());
    std::mt19937 rng(static_cast<unsigned>(riner::test::seed()));
    std::uniform_real_distribution<float> u(0.0f, 0.05f);
    for (cl_uint n : {1u, 64u, 1000u, 4096u}) {
      CAPTURE(n);
      std::vector<float> mu(n);
      for (float& v : mu) v = u(rng);
      double exact = 0.0;
      for (float v : mu) exact += v;
      const std::vector<cl_uint> offsets{0, n};
      riner::cl::Buffer<cl_uint> d_offsets(ctx, std::span<const cl_uint>(offsets));
      riner::cl::Buffer<float> d_mu(ctx, std::span<const float>(mu));
      riner::cl::Buffer<float> d_dx(ctx, std::span<const float>(std::vector<float>{1.0f}));
      riner::cl::Buffer<cl_uint> d_e(ctx, std::span<const cl_uint>(std::vector<cl_uint>{0}));
      // rho = 0 and alpha = beta0 large: the loss is the ray sum itself (beta ~ 1).
      riner::cl::Buffer<float> d_rho(ctx, std::span<const float>(std::vector<float>{0.0f}));
      riner::cl::Buffer<float> d_alpha(ctx, std::span<const float>(std::vector<float>{1.0f}));
      riner::cl::Buffer<float> d_beta(ctx, std::span<const float>(std::vector<float>{40.0f}));
      riner::cl::Buffer<float> d_dmu(ctx, n), d_loss(ctx, 1), g_a(ctx, 1), g_b(ctx, 1);
      g_a.write(std::vector<float>{0.0f});
      g_b.write(std::vector<float>{0.0f});
      riner::ops::RaySumOp(ctx).loss({&d_offsets, &d_dx, &d_e, &d_rho}, d_mu, d_alpha, d_beta, 1.0f,
                                     0.0f, d_dmu, d_loss, g_a, g_b);
      const double got = d_loss.read()[0];
      MESSAGE(n << " samples: relative error " << std::fabs(got - exact) / exact);
      CHECK(std::fabs(got - exact) <= 1e-5 * exact);
    }
  }
}
