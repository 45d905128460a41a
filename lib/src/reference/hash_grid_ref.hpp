// CPU twin of kernels/hash_grid.cl, in double: the multiresolution grid encoding and the
// scatter of its gradient. Layout and indexing as in model/parameter_layout.hpp.
#pragma once

#include <cstdint>
#include <vector>

#include "model/parameter_layout.hpp"

namespace riner::ref {

// out[level * features + f] for one normalised position (dims coordinates in [0, 1]).
void hash_grid_encode(const model::ParameterLayout& l, const double* params, const double* pos,
                      double* out);

// grad[...] += d_out scattered to the vertices the position interpolates.
void hash_grid_scatter(const model::ParameterLayout& l, const double* pos, const double* d_out,
                       double* grad);

// The parameter index of vertex `coords` at `level` (feature 0).
std::uint32_t hash_grid_index(const model::ParameterLayout& l, int level,
                              const std::uint32_t* coords);

// Batched, fp32 at the boundary like the device op: features [n][inputs].
std::vector<float> hash_grid_forward(const model::ParameterLayout& l,
                                     const std::vector<float>& params,
                                     const std::vector<float>& positions);
// Gradient of sum(d_features * features) with respect to every parameter (zero outside the grid).
std::vector<double> hash_grid_backward(const model::ParameterLayout& l,
                                       const std::vector<float>& positions,
                                       const std::vector<float>& d_features);

}  // namespace riner::ref
