#include "ops/alpha_factors.hpp"

#include "riner/error.hpp"

namespace riner::ops {

AlphaFactorsOp::AlphaFactorsOp(cl::Context& context, const model::ParameterLayout& layout)
    : context_(context),
      total_(layout.total),
      program_(context.program({"common", "alpha_factors"})),
      gradient_(*program_, "alpha_factors_gradient"),
      expand_(*program_, "alpha_factors_expand") {
  if (!layout.factored_alpha()) throw Error("alpha_factors: the layout has no factors");
  shape_.rows = static_cast<cl_uint>(layout.factor_rows);
  shape_.columns = static_cast<cl_uint>(layout.factor_columns);
  shape_.alpha_offset = static_cast<cl_uint>(layout.alpha_offset);
  shape_.factor_offset = static_cast<cl_uint>(layout.factor_offset);
}

void AlphaFactorsOp::check(const cl::Buffer<float>& params) const {
  if (params.size() != total_) throw Error("alpha_factors: buffer sizes do not match the layout");
}

void AlphaFactorsOp::gradient(const cl::Buffer<float>& params, cl::Buffer<float>& grad) {
  check(params);
  check(grad);
  gradient_.set_args(shape_, params, grad);
  context_.launch(gradient_, std::size_t{shape_.rows} + shape_.columns);
}

void AlphaFactorsOp::expand(cl::Buffer<float>& params) {
  check(params);
  expand_.set_args(shape_, params);
  context_.launch(expand_, std::size_t{shape_.rows} * shape_.columns);
}

}  // namespace riner::ops
