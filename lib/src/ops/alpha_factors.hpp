// Host side of kernels/alpha_factors.cl: alpha as row x column factors, the chain rule from
// each element's alpha0 gradient to the factors, and the product back into alpha0.
#pragma once

#include <memory>

#include "cl/buffer.hpp"
#include "cl/context.hpp"
#include "cl/program.hpp"
#include "model/parameter_layout.hpp"

namespace riner::ops {

// Host mirror of AlphaFactorShape in kernels/alpha_factors.cl.
struct AlphaFactorShape {
  cl_uint rows = 0;
  cl_uint columns = 0;
  cl_uint alpha_offset = 0;
  cl_uint factor_offset = 0;
};
static_assert(sizeof(AlphaFactorShape) == 16, "must match AlphaFactorShape in alpha_factors.cl");

class AlphaFactorsOp {
 public:
  // The layout must have factors (ParameterLayout::factored_alpha).
  AlphaFactorsOp(cl::Context& context, const model::ParameterLayout& layout);

  // Adds the factors' gradients to grad from its per-element alpha0 entries.
  void gradient(const cl::Buffer<float>& params, cl::Buffer<float>& grad);
  // alpha0 of every element = its row factor * its column factor.
  void expand(cl::Buffer<float>& params);

 private:
  void check(const cl::Buffer<float>& params) const;

  cl::Context& context_;
  AlphaFactorShape shape_;
  std::size_t total_;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel gradient_;
  cl::Kernel expand_;
};

}  // namespace riner::ops
