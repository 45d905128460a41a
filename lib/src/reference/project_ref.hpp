// CPU twins of ops::ProjectOp and ops::BackprojectOp: Joseph's method in double, the adjoint
// exact (same traversal), both deterministic (threads own disjoint outputs or private sums).
#pragma once

#include <vector>

#include "riner/geometry.hpp"

namespace riner::ref {

// Measurement [views][rows][elements] from a volume [nz][ny][nx].
std::vector<double> project(const Geometry& g, const std::vector<double>& volume);
std::vector<float> project(const Geometry& g, const std::vector<float>& volume);

// The adjoint: volume = A^T values.
std::vector<double> backproject_adjoint(const Geometry& g, const std::vector<double>& values);
std::vector<float> backproject_adjoint(const Geometry& g, const std::vector<float>& values);

}  // namespace riner::ref
