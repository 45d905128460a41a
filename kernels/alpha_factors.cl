// alpha_factors.cl: a detector response made of row and column factors,
// alpha0(r, c) = row[r] * column[c] (parameter_layout.hpp). The step writes each element's
// alpha0 gradient as for a free alpha0; these kernels carry it to the factors and back.
//   alpha_factors_gradient(f, params, grad)
//     one work-item per factor i < f.rows + f.columns: the chain rule through the product,
//     grad[row r] += sum_c grad0(r, c) column[c], grad[column c] += sum_r grad0(r, c) row[r],
//     summed in ascending order (deterministic). grad0 is left for Adam to clear; the alpha0
//     it moves is overwritten by alpha_factors_expand.
//   alpha_factors_expand(f, params)
//     one work-item per element e < f.rows * f.columns: alpha0[e] = row[e / columns] *
//     column[e % columns].
// No -D constants. CPU twin: lib/src/reference/alpha_factors_ref.cpp.

// Host mirror: ops::AlphaFactorShape (lib/src/ops/alpha_factors.hpp), 4 four-byte members.
typedef struct {
  uint rows;
  uint columns;
  uint alpha_offset;   // alpha0 of element 0
  uint factor_offset;  // row factor 0; column factor 0 follows the last row factor
} AlphaFactorShape;

__kernel void alpha_factors_gradient(const AlphaFactorShape f, __global const float* params,
                                     __global float* grad) {
  const uint i = get_global_id(0);
  if (i >= f.rows + f.columns) return;
  __global const float* g0 = grad + f.alpha_offset;
  __global const float* row = params + f.factor_offset;
  __global const float* column = row + f.rows;
  float sum = 0.0f;
  if (i < f.rows) {
    for (uint c = 0; c < f.columns; ++c) sum += g0[i * f.columns + c] * column[c];
  } else {
    const uint c = i - f.rows;
    for (uint r = 0; r < f.rows; ++r) sum += g0[r * f.columns + c] * row[r];
  }
  grad[f.factor_offset + i] += sum;
}

__kernel void alpha_factors_expand(const AlphaFactorShape f, __global float* params) {
  const uint e = get_global_id(0);
  if (e >= f.rows * f.columns) return;
  __global const float* row = params + f.factor_offset;
  params[f.alpha_offset + e] = row[e / f.columns] * row[f.rows + e % f.columns];
}
