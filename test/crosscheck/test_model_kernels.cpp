// kernels/hash_grid.cl, mlp.cl, ray_sum.cl and adam.cl against their CPU twins on fresh random
// inputs.
#include <doctest/doctest.h>

#include <random>

#include "cl/buffer.hpp"
#include "model/parameter_layout.hpp"
#include "ops/adam.hpp"
#include "ops/hash_grid.hpp"
#include "ops/mlp.hpp"
#include "ops/ray_sum.hpp"
#include "reference/adam_ref.hpp"
#include "reference/hash_grid_ref.hpp"
#include "reference/mlp_ref.hpp"
#include "reference/ray_sum_ref.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"

namespace {

riner::cl::Context& ctx() { return riner::test::device().context(); }

std::vector<float> uniform(std::size_t n, float lo, float hi, std::uint64_t salt) {
  std::mt19937_64 rng(riner::test::seed() + salt);
  std::uniform_real_distribution<float> u(lo, hi);
  std::vector<float> v(n);
  for (float& x : v) x = u(rng);
  return v;
}

// Positions at least 1e-3 cells from every level's cell boundaries: float (device) and double
// (reference) must pick the same cells.
std::vector<float> safe_positions(const riner::model::ParameterLayout& l, std::size_t n,
                                  std::uint64_t salt) {
  std::vector<float> out;
  std::vector<float> candidates = uniform(n * l.dims * 4, 0.0f, 1.0f, salt);
  for (std::size_t i = 0; i + l.dims <= candidates.size() && out.size() < n * l.dims; i += l.dims) {
    bool ok = true;
    for (int d = 0; d < l.dims && ok; ++d) {
      for (const auto& level : l.grid) {
        const double x = candidates[i + d] * static_cast<double>(level.scale) + 0.5;
        const double frac = x - std::floor(x);
        ok = ok && frac > 1e-3 && frac < 1.0 - 1e-3;
      }
    }
    if (ok)
      out.insert(out.end(), candidates.begin() + static_cast<long>(i),
                 candidates.begin() + static_cast<long>(i + l.dims));
  }
  REQUIRE(out.size() == n * l.dims);
  return out;
}

}  // namespace

TEST_SUITE("model_kernels") {
  TEST_CASE("hash grid forward and backward, 2D and 3D, dense and hashed levels") {
    for (int dims : {2, 3}) {
      CAPTURE(dims);
      const auto l = riner::model::make_layout(dims, {6, 2, 12, 4, 128}, {16, 1}, 1);
      const std::vector<float> params = uniform(l.total, -1.0f, 1.0f, 10);
      const std::vector<float> positions = safe_positions(l, 777, 11);
      const std::size_t n = positions.size() / dims;
      riner::cl::Buffer<float> d_params(ctx(), std::span<const float>(params));
      riner::cl::Buffer<float> d_positions(ctx(), std::span<const float>(positions));
      riner::cl::Buffer<float> d_features(ctx(), n * l.inputs);
      riner::ops::HashGridOp op(ctx(), l);
      op.forward(d_params, d_positions, d_features);
      // Sums of 2^dims products in fp32: ~1e-7 relative.
      const auto forward = riner::test::compare(
          d_features.read(), riner::ref::hash_grid_forward(l, params, positions));
      CHECK_MESSAGE(forward.rms_rel < 1e-5, forward.describe());
      const std::vector<float> d_out = uniform(n * l.inputs, -1.0f, 1.0f, 12);
      riner::cl::Buffer<float> d_grad(ctx(),
                                      std::span<const float>(std::vector<float>(l.total, 0.0f)));
      riner::cl::Buffer<float> d_dout(ctx(), std::span<const float>(d_out));
      op.backward(d_positions, d_dout, d_grad);
      // Float atomics in arbitrary order over ~777 points: 1e-5 relative is ample.
      const auto backward =
          riner::test::compare(d_grad.read(), riner::ref::hash_grid_backward(l, positions, d_out));
      CHECK_MESSAGE(backward.rms_rel < 1e-4, backward.describe());
    }
  }

  TEST_CASE("MLP forward and backward, widths 16 and 48, one to three hidden layers") {
    for (const riner::NetworkConfig net :
         {riner::NetworkConfig{16, 1}, riner::NetworkConfig{48, 3}}) {
      CAPTURE(net.width);
      const auto l = riner::model::make_layout(2, {5, 2, 10, 4, 32}, net, 1);
      std::vector<float> params = riner::model::initial_parameters(l, 3);
      const std::size_t n = 301;
      const std::vector<float> inputs = uniform(n * l.inputs, -1.0f, 1.0f, 20);
      riner::cl::Buffer<float> d_params(ctx(), std::span<const float>(params));
      riner::cl::Buffer<float> d_inputs(ctx(), std::span<const float>(inputs));
      riner::cl::Buffer<float> d_out(ctx(), n);
      riner::ops::MlpOp op(ctx(), l);
      op.forward(d_params, d_inputs, d_out);
      const auto forward =
          riner::test::compare(d_out.read(), riner::ref::mlp_forward_batch(l, params, inputs));
      CHECK_MESSAGE(forward.rms_rel < 1e-5, forward.describe());
      const std::vector<float> d_outputs = uniform(n, -1.0f, 1.0f, 21);
      riner::cl::Buffer<float> d_dout(ctx(), std::span<const float>(d_outputs));
      riner::cl::Buffer<float> d_grad(ctx(),
                                      std::span<const float>(std::vector<float>(l.total, 0.0f)));
      riner::cl::Buffer<float> d_din(ctx(), n * l.inputs);
      op.backward(d_params, d_inputs, d_dout, d_grad, d_din);
      std::vector<double> ref_din;
      const std::vector<double> ref_grad =
          riner::ref::mlp_backward_batch(l, params, inputs, d_outputs, &ref_din);
      const auto grad = riner::test::compare(d_grad.read(), ref_grad);
      CHECK_MESSAGE(grad.rms_rel < 1e-4, grad.describe());
      const auto din = riner::test::compare(d_din.read(), ref_din);
      CHECK_MESSAGE(din.rms_rel < 1e-5, din.describe());
    }
  }

  TEST_CASE("forward model and loss, with non-finite measurements and clamped alphas") {
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
    rho[3] = INFINITY;
    rho[7] = NAN;
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
    op.loss({&d_offsets, &d_dx, &d_elements, &d_rho}, d_mu, d_alpha, d_beta, 0.3f, d_dmu, d_loss,
            g_alpha, g_beta);
    std::vector<double> loss(rays), dmu(mu.size()), ga(elements, 0.0), gb(elements, 0.0);
    for (std::size_t r = 0; r < rays; ++r) {
      double sum = 0.0;
      for (cl_uint k = offsets[r]; k < offsets[r + 1]; ++k) sum += mu[k];
      const auto rl =
          riner::ref::ray_loss(sum * dx[r], alpha0[element[r]], beta0[element[r]], rho[r], 0.3);
      loss[r] = rl.loss;
      for (cl_uint k = offsets[r]; k < offsets[r + 1]; ++k) dmu[k] = rl.d_sum * dx[r];
      ga[element[r]] += rl.d_alpha0;
      gb[element[r]] += rl.d_beta0;
    }
    CHECK(riner::test::compare(d_loss.read(), loss).rms_rel < 1e-4);
    CHECK(riner::test::compare(d_dmu.read(), dmu).rms_rel < 1e-5);
    CHECK(riner::test::compare(g_alpha.read(), ga).rms_rel < 1e-4);
    CHECK(riner::test::compare(g_beta.read(), gb).rms_rel < 1e-4);
    CHECK(g_alpha.read()[2] == 0.0f);
    for (float v : d_loss.read()) CHECK(std::isfinite(v));
  }

  TEST_CASE("Adam over a gradient plus split-K slices, per-group learning rates, several steps") {
    const std::size_t n = 1000;
    const std::size_t slice_offset = 200, slice_count = 300, slices = 3;
    std::vector<float> params = uniform(n, -1.0f, 1.0f, 40);
    riner::ref::AdamSettings rs;
    rs.learning_rate = 1e-2;
    rs.alpha_offset = 900;
    rs.alpha_learning_rate = 3e-2;
    rs.beta_offset = 950;
    rs.beta_learning_rate = 0.0;
    rs.beta2 = 0.99;
    rs.epsilon = 1e-15;
    riner::ops::AdamSettings ds{rs.learning_rate,
                                rs.alpha_offset,
                                rs.alpha_learning_rate,
                                rs.beta_offset,
                                rs.beta_learning_rate,
                                rs.beta1,
                                rs.beta2,
                                rs.epsilon};
    std::vector<double> p(params.begin(), params.end()), m(n, 0.0), v(n, 0.0);
    riner::cl::Buffer<float> d_params(ctx(), std::span<const float>(params));
    riner::cl::Buffer<float> d_grad(ctx(), n);
    riner::cl::Buffer<float> d_slices(ctx(), slice_count * slices);
    riner::ops::AdamOp op(ctx(), n);
    for (int step = 1; step <= 5; ++step) {
      const std::vector<float> g = uniform(n, -1.0f, 1.0f, 40 + step);
      const std::vector<float> s = uniform(slice_count * slices, -1.0f, 1.0f, 60 + step);
      d_grad.write(g);
      d_slices.write(s);
      op.step(ds, step, d_params, d_grad, {&d_slices, slice_offset, slice_count, slices});
      std::vector<double> total(g.begin(), g.end());
      for (std::size_t k = 0; k < s.size(); ++k) total[slice_offset + k % slice_count] += s[k];
      riner::ref::adam_step(rs, step, total, p, m, v);
      for (float x : d_grad.read()) REQUIRE(x == 0.0f);  // cleared for the next step
    }
    // Five fp32 updates of parameters of order 1: rounding leaves ~1e-7.
    const auto stats = riner::test::compare(d_params.read(), p);
    CHECK_MESSAGE(stats.max_abs < 1e-6, stats.describe());
    CHECK(d_params.read()[975] == params[975]);  // beta learning rate 0: unchanged
  }
}
