#include "reference/alpha_factors_ref.hpp"

namespace riner::ref {

void alpha_factors_gradient(const model::ParameterLayout& l, const std::vector<double>& params,
                            std::vector<double>& grad) {
  const std::size_t rows = l.factor_rows;
  const std::size_t columns = l.factor_columns;
  const double* row = params.data() + l.factor_offset;
  const double* column = row + rows;
  const double* g0 = grad.data() + l.alpha_offset;
  std::vector<double> sums(rows + columns, 0.0);
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < columns; ++c) {
      sums[r] += g0[r * columns + c] * column[c];
      sums[rows + c] += g0[r * columns + c] * row[r];
    }
  }
  for (std::size_t i = 0; i < sums.size(); ++i) grad[l.factor_offset + i] += sums[i];
}

void alpha_factors_expand(const model::ParameterLayout& l, std::vector<double>& params) {
  const std::size_t rows = l.factor_rows;
  const std::size_t columns = l.factor_columns;
  for (std::size_t e = 0; e < rows * columns; ++e) {
    params[l.alpha_offset + e] =
        params[l.factor_offset + e / columns] * params[l.factor_offset + rows + e % columns];
  }
}

}  // namespace riner::ref
