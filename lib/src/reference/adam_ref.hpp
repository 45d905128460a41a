// CPU twin of kernels/adam.cl: Adam (Kingma & Ba) as PyTorch computes it, over the whole flat
// parameter buffer; every parameter is updated every step (entries with a zero gradient decay
// their moments too), except entries below sparse_below with a zero gradient (lazy Adam).
#pragma once

#include <cstddef>
#include <vector>

#include "model/adam_settings.hpp"

namespace riner::ref {

using AdamSettings = model::AdamSettings;

// step counts from 1.
void adam_step(const AdamSettings& s, int step, const std::vector<double>& grad,
               std::vector<double>& params, std::vector<double>& m, std::vector<double>& v);

}  // namespace riner::ref
