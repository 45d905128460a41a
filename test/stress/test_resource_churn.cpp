// Creating and destroying OpenCL objects in volume leaks nothing.
#include <doctest/doctest.h>

#include "cl/buffer.hpp"
#include "cl/device_access.hpp"
#include "ops/vector_ops.hpp"
#include "support/fixture.hpp"

TEST_SUITE("resource_churn") {
  TEST_CASE("buffers and launches in a loop leave no live buffers") {
    riner::cl::Context& ctx = riner::cl::context_of(riner::test::device());
    const long before = riner::cl::live_buffer_count();
    riner::ops::VectorOps ops(ctx);
    for (int i = 0; i < 2000; ++i) {
      riner::cl::Buffer<float> x(ctx, 1024 + static_cast<std::size_t>(i % 7));
      riner::cl::Buffer<float> y(ctx, x.size());
      x.fill(1.0f);
      y.fill(0.0f);
      ops.axpy(1.0f, x, y);
      riner::cl::Buffer<float> moved = std::move(y);
      CHECK(moved.size() == x.size());
    }
    ctx.finish();
    CHECK(riner::cl::live_buffer_count() == before);
  }

  TEST_CASE("devices opened and closed repeatedly") {
    for (int i = 0; i < 20; ++i) {
      riner::Device device = riner::Device::open();
      riner::ops::VectorOps ops(riner::cl::context_of(device));
    }
  }
}
