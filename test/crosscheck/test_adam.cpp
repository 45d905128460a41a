// kernels/adam.cl (ops::AdamOp) against reference/adam_ref on fresh random inputs.
#include <doctest/doctest.h>

#include <cmath>

#include "cl/buffer.hpp"
#include "cl/device_access.hpp"
#include "ops/adam.hpp"
#include "reference/adam_ref.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"
#include "support/random_inputs.hpp"
#include "support/tolerances.hpp"

namespace {

using riner::test::uniform;

riner::cl::Context& ctx() { return riner::cl::context_of(riner::test::device()); }

}  // namespace

TEST_SUITE("adam") {
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
    CHECK_MESSAGE(stats.max_abs < riner::test::tolerance::kElementwise, stats.describe());
    CHECK(d_params.read()[975] == params[975]);  // beta learning rate 0: unchanged
  }

  TEST_CASE("lazy Adam: entries below sparse_below with a zero gradient keep value and moments") {
    // Neither a multiple of the kernel's 8 lanes: a group straddles the sparse boundary and
    // the last group is short.
    const std::size_t n = 603, sparse_below = 403;
    const std::vector<float> params = uniform(n, -1.0f, 1.0f, 80);
    riner::ref::AdamSettings rs;
    rs.learning_rate = 1e-2;
    rs.sparse_below = sparse_below;
    std::vector<double> p(params.begin(), params.end()), m(n, 0.0), v(n, 0.0);
    riner::cl::Buffer<float> d_params(ctx(), std::span<const float>(params));
    riner::cl::Buffer<float> d_grad(ctx(), n);
    riner::ops::AdamOp op(ctx(), n);
    for (int step = 1; step <= 6; ++step) {
      std::vector<float> g = uniform(n, -1.0f, 1.0f, 90 + step);
      // Entries 0..99 are touched on the first step only, 100..199 never, 450..499 (dense) on
      // the first step only, the rest every step.
      for (std::size_t i = 0; i < 200; ++i) {
        if (step > 1 || i >= 100) g[i] = 0.0f;
      }
      for (std::size_t i = 450; i < 500; ++i) {
        if (step > 1) g[i] = 0.0f;
      }
      d_grad.write(g);
      op.step(rs, step, d_params, d_grad);
      riner::ref::adam_step(rs, step, std::vector<double>(g.begin(), g.end()), p, m, v);
    }
    const std::vector<float> got = d_params.read();
    const auto stats = riner::test::compare(got, p);
    CHECK_MESSAGE(stats.max_abs < riner::test::tolerance::kElementwise, stats.describe());
    for (std::size_t i = 100; i < 200; ++i) REQUIRE(got[i] == params[i]);  // never touched
    // Touched once: moved by the first step alone, then left (dense Adam would keep drifting).
    CHECK(std::fabs(got[5] - params[5]) == doctest::Approx(1e-2).epsilon(1e-3));
    // Dense, touched once: the first step's momentum keeps moving it.
    CHECK(std::fabs(got[470] - params[470]) > 2e-2);
  }
}
