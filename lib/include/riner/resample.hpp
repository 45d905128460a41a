// Putting a ground-truth image or volume of any voxel size onto a geometry's grid, for
// simulation (`riner simulate --phantom FILE --phantom-spacing-mm ...`).
#pragma once

#include <vector>

#include "riner/array.hpp"
#include "riner/geometry.hpp"

namespace riner {

// `image` ([y, x] or [z, y, x]) with voxel sizes `spacing_mm` (one per axis, same order), both
// grids centred on the rotation axis, sampled at the centres of the geometry's voxels:
// bilinear (2D) or trilinear (3D) between the image's voxel centres, and 0 beyond half a voxel
// outside them (the image is taken to hold all of the object). InputError when the ranks
// differ, a spacing is not positive and finite, or the image is empty.
Array resample_to_grid(const Array& image, const std::vector<double>& spacing_mm,
                       const Geometry& geometry);

}  // namespace riner
