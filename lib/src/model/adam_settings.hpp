// Adam's settings for one step, shared by the OpenCL op (ops/adam.hpp) and its CPU twin
// (reference/adam_ref.hpp) so the two cannot drift apart.
#pragma once

#include <cstddef>

namespace riner::model {

struct AdamSettings {
  double learning_rate = 1e-3;
  // alpha0 and beta0 (from these offsets on) have learning rates of their own.
  std::size_t alpha_offset = static_cast<std::size_t>(-1);
  double alpha_learning_rate = 1e-3;
  std::size_t beta_offset = static_cast<std::size_t>(-1);
  double beta_learning_rate = 1e-3;
  double beta1 = 0.9;
  double beta2 = 0.999;
  double epsilon = 1e-8;
  // Entries before this one whose gradient is exactly 0 this step are left as they are (value
  // and moments): lazy Adam over the hash grid, whose entries a batch mostly does not touch.
  std::size_t sparse_below = 0;
};

}  // namespace riner::model
