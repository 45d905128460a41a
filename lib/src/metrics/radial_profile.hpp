// The angular mean of a 2D image about the grid centre (the rotation axis), in 1-pixel radius
// bins (each pixel centre rounded to the nearest radius); the ring index and the quality
// report both read it.
#pragma once

#include <cstddef>
#include <vector>

#include "riner/array.hpp"

namespace riner::metrics {

// mean[r], count[r] for r < bins; non-finite pixels are left out; mean is 0 where count is 0.
void radial_means(const Array& image, std::size_t bins, std::vector<double>& mean,
                  std::vector<double>& count);

}  // namespace riner::metrics
