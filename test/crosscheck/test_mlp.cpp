// kernels/mlp.cl (ops::MlpOp) against reference/mlp_ref on fresh random inputs.
#include <doctest/doctest.h>

#include "cl/buffer.hpp"
#include "cl/device_access.hpp"
#include "model/parameter_layout.hpp"
#include "ops/mlp.hpp"
#include "reference/mlp_ref.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"
#include "support/random_inputs.hpp"
#include "support/tolerances.hpp"

namespace {

using riner::test::uniform;

riner::cl::Context& ctx() { return riner::cl::context_of(riner::test::device()); }

}  // namespace

TEST_SUITE("mlp") {
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
      CHECK_MESSAGE(forward.rms_rel < riner::test::tolerance::kOnePass, forward.describe());
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
      CHECK_MESSAGE(grad.rms_rel < riner::test::tolerance::kChained, grad.describe());
      const auto din = riner::test::compare(d_din.read(), ref_din);
      CHECK_MESSAGE(din.rms_rel < riner::test::tolerance::kOnePass, din.describe());
    }
  }
}
