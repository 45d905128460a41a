// kernels/hash_grid.cl (ops::HashGridOp) against reference/hash_grid_ref on fresh random inputs.
#include <doctest/doctest.h>

#include <cmath>

#include "cl/buffer.hpp"
#include "cl/device_access.hpp"
#include "model/parameter_layout.hpp"
#include "ops/hash_grid.hpp"
#include "reference/hash_grid_ref.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"
#include "support/random_inputs.hpp"
#include "support/tolerances.hpp"

namespace {

using riner::test::uniform;

riner::cl::Context& ctx() { return riner::cl::context_of(riner::test::device()); }

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

TEST_SUITE("hash_grid") {
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
      CHECK_MESSAGE(forward.rms_rel < riner::test::tolerance::kOnePass, forward.describe());
      const std::vector<float> d_out = uniform(n * l.inputs, -1.0f, 1.0f, 12);
      riner::cl::Buffer<float> d_grad(ctx(),
                                      std::span<const float>(std::vector<float>(l.total, 0.0f)));
      riner::cl::Buffer<float> d_dout(ctx(), std::span<const float>(d_out));
      op.backward(d_positions, d_dout, d_grad);
      // Float atomics in arbitrary order over ~777 points: sums in another order.
      const auto backward =
          riner::test::compare(d_grad.read(), riner::ref::hash_grid_backward(l, positions, d_out));
      CHECK_MESSAGE(backward.rms_rel < riner::test::tolerance::kChained, backward.describe());
    }
  }
}
