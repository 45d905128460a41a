// CPU twins of ops::FbpOp: filtering by FFT with zero padding (a different algorithm from the
// device's direct convolution, same result) and the weighted backprojection, both in double.
#pragma once

#include <vector>

#include "riner/geometry.hpp"

namespace riner::ref {

// Every detector row of `in` ([lines][n_u]) convolved with taps (length 2 n_u - 1).
std::vector<double> fbp_filter(const std::vector<double>& in, std::size_t n_u,
                               const std::vector<double>& taps);

// Onto the axial slices first_slice + s * slice_step, s < slices (0: all of the volume's).
std::vector<double> fbp_backproject(const Geometry& g, const std::vector<double>& filtered,
                                    const std::vector<double>& view_weights,
                                    std::size_t first_slice = 0, std::size_t slice_step = 1,
                                    std::size_t slices = 0);

}  // namespace riner::ref
