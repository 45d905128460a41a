#include "ops/vector_ops.hpp"

#include "riner/error.hpp"

namespace riner::ops {

VectorOps::VectorOps(cl::Context& context)
    : context_(context),
      program_(context.program({"common", "vector_ops"})),
      axpy_(*program_, "vector_ops_axpy"),
      sum_(*program_, "vector_ops_sum"),
      fill_(*program_, "vector_ops_fill") {}

void VectorOps::axpy(float a, const cl::Buffer<float>& x, cl::Buffer<float>& y) {
  if (x.size() != y.size()) throw Error("vector_ops axpy: x and y differ in size");
  const auto n = static_cast<cl_uint>(x.size());
  axpy_.set_args(n, a, x, y);
  context_.launch(axpy_, x.size());
}

void VectorOps::sum(const cl::Buffer<float>& x, cl::Buffer<float>& total) {
  if (total.size() != 1) throw Error("vector_ops sum: total must hold one value");
  const auto n = static_cast<cl_uint>(x.size());
  sum_.set_args(n, x, total);
  context_.launch(sum_, x.size());
}

}  // namespace riner::ops

namespace riner::ops {

void VectorOps::fill(cl::Buffer<float>& y, float value) {
  const auto n = static_cast<cl_uint>(y.size());
  fill_.set_args(n, value, y);
  context_.launch(fill_, y.size());
}

}  // namespace riner::ops
