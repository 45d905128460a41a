// CPU twin of ops::AlphaFactorsOp (kernels/alpha_factors.cl), in double.
#pragma once

#include <vector>

#include "model/parameter_layout.hpp"

namespace riner::ref {

// grad[row r] += sum_c grad[alpha0(r, c)] column[c]; grad[column c] += sum_r grad[alpha0(r, c)]
// row[r]. No-op without factors.
void alpha_factors_gradient(const model::ParameterLayout& layout, const std::vector<double>& params,
                            std::vector<double>& grad);
// alpha0(r, c) = row[r] column[c]. No-op without factors.
void alpha_factors_expand(const model::ParameterLayout& layout, std::vector<double>& params);

}  // namespace riner::ref
