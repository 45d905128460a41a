// A detector element whose response differs from its neighbours' adds a stripe to the sinogram
// (a ring to the image). Its mean over the views against its neighbours' tells it from the
// object, whose mean over the views is smooth along the detector: every point of it sweeps a
// range of elements.
#pragma once

#include "riner/array.hpp"
#include "riner/geometry.hpp"

namespace riner::preprocessing {

// Each element's stripe taken off every view: its mean over the views less the median of the
// means of the elements within `reach` of it on its row. Non-finite readings are left out of
// the means and stay as they are.
void remove_stripes(Array& measurement, const Geometry& g, long reach = 25);

}  // namespace riner::preprocessing
