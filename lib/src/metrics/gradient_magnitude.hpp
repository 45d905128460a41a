// The edge measures' gradient: of the quality report (no reference) and of riner compare
// (against the truth), the same per pixel.
#pragma once

#include <vector>

#include "riner/array.hpp"

namespace riner::metrics {

// |Sobel gradient| / 8 (a central difference per pixel, 1/mm per pixel for mu) of a 2D image
// after a Gaussian of `smoothing_px` (so that pixel noise does not pass for edges); NaN on
// the border row and column and where a neighbour is not finite.
std::vector<double> gradient_magnitude(const Array& image, double smoothing_px);

}  // namespace riner::metrics
