// CPU twin of ops::VectorOps (kernels/vector_ops.cl), accumulating in double.
#pragma once

#include <span>

namespace riner::ref {

void vector_axpy(float a, std::span<const float> x, std::span<float> y);
double vector_sum(std::span<const float> x);

}  // namespace riner::ref
