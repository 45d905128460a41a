// A detector element whose response differs from its neighbours' adds a stripe to the sinogram
// (a ring to the image). Its mean over the views against its neighbours' tells it from the
// object, whose mean over the views is smooth along the detector: every point of it sweeps a
// range of elements.
#pragma once

#include <cstddef>
#include <vector>

#include "riner/array.hpp"
#include "riner/geometry.hpp"

namespace riner::preprocessing {

// Per element of rows of n_u values (an element's mean over the views, say): the q quantile
// of the finite values within `reach` of it on its row, itself included; NaN where its own
// value is not finite.
std::vector<double> row_quantile(const std::vector<double>& values, std::size_t n_u,
                                 std::size_t reach, double q);

// Each element's stripe taken off every view: its mean over the views less the median of the
// means of the elements within `reach` of it on its row. Non-finite readings are left out of
// the means and stay as they are.
void remove_stripes(Array& measurement, const Geometry& g, std::size_t reach = 25);

}  // namespace riner::preprocessing
