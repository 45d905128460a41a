// kernels/vector_ops.cl against its CPU twin on random inputs.
#include <doctest/doctest.h>

#include <random>

#include "cl/buffer.hpp"
#include "cl/device_access.hpp"
#include "ops/vector_ops.hpp"
#include "reference/vector_ops_ref.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"
#include "support/tolerances.hpp"

TEST_SUITE("vector_ops") {
  TEST_CASE("axpy matches the reference to float rounding") {
    riner::cl::Context& ctx = riner::cl::context_of(riner::test::device());
    std::mt19937 rng(static_cast<unsigned>(riner::test::seed()));
    std::uniform_real_distribution<float> u(-10.0f, 10.0f);
    for (std::size_t n : {1u, 31u, 1000u, 65537u}) {
      std::vector<float> x(n);
      std::vector<float> y(n);
      for (std::size_t i = 0; i < n; ++i) {
        x[i] = u(rng);
        y[i] = u(rng);
      }
      riner::cl::Buffer<float> dx(ctx, std::span<const float>(x));
      riner::cl::Buffer<float> dy(ctx, std::span<const float>(y));
      riner::ops::VectorOps(ctx).axpy(-1.75f, dx, dy);
      riner::ref::vector_axpy(-1.75f, x, y);
      // One multiply-add per element: the device may fuse it, so allow one rounding (2^-23)
      // relative to the operands' scale.
      const auto stats = riner::test::compare(dy.read(), y, 10.0);
      CHECK_MESSAGE(stats.max_rel < riner::test::tolerance::kElementwise, stats.describe());
    }
  }

  TEST_CASE("atomic sum matches the double reference; repeats agree to rounding") {
    riner::cl::Context& ctx = riner::cl::context_of(riner::test::device());
    std::mt19937 rng(static_cast<unsigned>(riner::test::seed()) + 1);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    std::vector<float> x(20000);
    for (float& v : x) v = u(rng);
    const double want = riner::ref::vector_sum(x);
    riner::cl::Buffer<float> dx(ctx, std::span<const float>(x));
    for (int repeat = 0; repeat < 3; ++repeat) {
      riner::cl::Buffer<float> total(ctx, 1);
      riner::ops::VectorOps(ctx).fill(total, 0.0f);
      riner::ops::VectorOps(ctx).sum(dx, total);
      // 20000 float additions in arbitrary order: error grows like n * eps * |sum| at worst.
      CHECK(total.read()[0] == doctest::Approx(want).epsilon(20000 * 6e-8));
    }
  }
}

TEST_SUITE("vector_ops") {
  TEST_CASE("fill sets every element, at odd sizes") {
    riner::cl::Context& ctx = riner::cl::context_of(riner::test::device());
    for (std::size_t n : {1u, 13u, 1024u}) {
      riner::cl::Buffer<float> y(ctx, n);
      riner::ops::VectorOps(ctx).fill(y, -2.5f);
      CHECK(y.read() == std::vector<float>(n, -2.5f));
    }
  }
}
