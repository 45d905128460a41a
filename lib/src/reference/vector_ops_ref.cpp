#include "reference/vector_ops_ref.hpp"

#include <Eigen/Core>

#include "riner/error.hpp"

namespace riner::ref {

void vector_axpy(float a, std::span<const float> x, std::span<float> y) {
  if (x.size() != y.size()) throw Error("vector_axpy: x and y differ in size");
  Eigen::Map<const Eigen::VectorXf> xv(x.data(), static_cast<Eigen::Index>(x.size()));
  Eigen::Map<Eigen::VectorXf> yv(y.data(), static_cast<Eigen::Index>(y.size()));
  yv += a * xv;
}

double vector_sum(std::span<const float> x) {
  Eigen::Map<const Eigen::VectorXf> xv(x.data(), static_cast<Eigen::Index>(x.size()));
  return xv.cast<double>().sum();
}

}  // namespace riner::ref
