// kernels/ray_sum.cl (ops::RaySumOp) against reference/ray_sum_ref on fresh random inputs.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "cl/buffer.hpp"
#include "cl/device_access.hpp"
#include "ops/ray_sum.hpp"
#include "reference/ray_sum_ref.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"
#include "support/random_inputs.hpp"
#include "support/tolerances.hpp"

namespace {

using riner::test::uniform;

riner::cl::Context& ctx() { return riner::cl::context_of(riner::test::device()); }

}  // namespace

TEST_SUITE("ray_sum") {
  TEST_CASE("forward model and loss, with non-finite measurements, bounds and clamped alphas") {
    const std::size_t rays = 200;
    const std::size_t elements = 17;
    std::vector<cl_uint> offsets{0};
    std::mt19937 rng(static_cast<unsigned>(riner::test::seed()) + 30);
    for (std::size_t r = 0; r < rays; ++r) offsets.push_back(offsets.back() + 1 + rng() % 40);
    const std::vector<float> mu = uniform(offsets.back(), 0.0f, 0.05f, 31);
    const std::vector<float> dx = uniform(rays, 0.5f, 1.5f, 32);
    std::vector<cl_uint> element(rays);
    for (cl_uint& e : element) e = static_cast<cl_uint>(rng() % elements);
    std::vector<float> rho = uniform(rays, 0.0f, 1.0f, 33);
    // +inf: a bound at the floor, met by some rays (no loss) and not by others.
    for (std::size_t r = 3; r < rays; r += 9) rho[r] = INFINITY;
    rho[7] = NAN;
    rho[8] = -INFINITY;
    const float floor = 0.6f;
    std::vector<float> alpha0 = uniform(elements, 0.7f, 1.3f, 34);
    alpha0[2] = -0.5f;  // clamped to 1e-8: no alpha gradient
    const std::vector<float> beta0 = uniform(elements, -2.0f, 2.0f, 35);
    riner::cl::Buffer<cl_uint> d_offsets(ctx(), std::span<const cl_uint>(offsets));
    riner::cl::Buffer<float> d_mu(ctx(), std::span<const float>(mu)),
        d_dx(ctx(), std::span<const float>(dx));
    riner::cl::Buffer<cl_uint> d_elements(ctx(), std::span<const cl_uint>(element));
    riner::cl::Buffer<float> d_rho(ctx(), std::span<const float>(rho));
    riner::cl::Buffer<float> d_alpha(ctx(), std::span<const float>(alpha0)),
        d_beta(ctx(), std::span<const float>(beta0));
    riner::cl::Buffer<float> d_dmu(ctx(), mu.size()), d_loss(ctx(), rays);
    riner::cl::Buffer<float> g_alpha(ctx(),
                                     std::span<const float>(std::vector<float>(elements, 0.0f)));
    riner::cl::Buffer<float> g_beta(ctx(),
                                    std::span<const float>(std::vector<float>(elements, 0.0f)));
    riner::ops::RaySumOp op(ctx());
    op.loss({&d_offsets, &d_dx, &d_elements, &d_rho}, d_mu, d_alpha, d_beta, 0.3f, floor, d_dmu,
            d_loss, g_alpha, g_beta);
    std::vector<double> loss(rays), dmu(mu.size()), ga(elements, 0.0), gb(elements, 0.0);
    int met = 0, unmet = 0;
    for (std::size_t r = 0; r < rays; ++r) {
      double sum = 0.0;
      for (cl_uint k = offsets[r]; k < offsets[r + 1]; ++k) sum += mu[k];
      const auto rl = riner::ref::ray_loss(sum * dx[r], alpha0[element[r]], beta0[element[r]],
                                           rho[r], 0.3, floor);
      loss[r] = rl.loss;
      if (std::isinf(rho[r]) && rho[r] > 0.0f) {
        const double inside = -std::log(std::max<double>(alpha0[element[r]], 1e-8)) + sum * dx[r];
        // Met: no loss and no gradient; unmet: the loss of a reading at the floor.
        const bool is_met = inside >= floor;
        met += is_met;
        unmet += !is_met;
        if (is_met) CHECK(rl.loss == 0.0);
        if (!is_met) CHECK(rl.loss > 0.0);
      }
      for (cl_uint k = offsets[r]; k < offsets[r + 1]; ++k) dmu[k] = rl.d_sum * dx[r];
      ga[element[r]] += rl.d_alpha0;
      gb[element[r]] += rl.d_beta0;
    }
    CHECK(riner::test::compare(d_loss.read(), loss).rms_rel < riner::test::tolerance::kChained);
    CHECK(riner::test::compare(d_dmu.read(), dmu).rms_rel < riner::test::tolerance::kOnePass);
    CHECK(riner::test::compare(g_alpha.read(), ga).rms_rel < riner::test::tolerance::kChained);
    CHECK(riner::test::compare(g_beta.read(), gb).rms_rel < riner::test::tolerance::kChained);
    CHECK(g_alpha.read()[2] == 0.0f);
    CHECK(met > 0);
    CHECK(unmet > 0);
    for (float v : d_loss.read()) CHECK(std::isfinite(v));
  }
}
