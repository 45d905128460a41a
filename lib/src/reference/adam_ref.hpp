// CPU twin of kernels/adam.cl: Adam (Kingma & Ba) as PyTorch computes it, over the whole flat
// parameter buffer; every parameter is updated every step (entries with a zero gradient decay
// their moments too).
#pragma once

#include <cstddef>
#include <vector>

namespace riner::ref {

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
};

// step counts from 1.
void adam_step(const AdamSettings& s, int step, const std::vector<double>& grad,
               std::vector<double>& params, std::vector<double>& m, std::vector<double>& v);

}  // namespace riner::ref
