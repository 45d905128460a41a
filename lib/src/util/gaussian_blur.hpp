// A Gaussian blur along every axis of an image or volume: edge voxels repeated beyond the
// border, weights out to 3 sigma, the last axis first (each pass stored in float).
#pragma once

#include <cstddef>
#include <vector>

namespace riner::util {

std::vector<float> gaussian_blur(const std::vector<float>& data,
                                 const std::vector<std::size_t>& shape, double sigma_px);

}  // namespace riner::util
