// Step 2 of the air carving (occupancy.hpp): a voxel is air where enough views certify every
// detector element of its shadow as reading air.
#pragma once

#include <cstdint>
#include <vector>

#include "riner/geometry.hpp"

namespace riner::model {

// Per voxel of g's grid (C order): 0 where at least min_views views certify its shadow, 1
// elsewhere. The shadow is that of a sphere circumscribing the voxel, widened by `widen`
// elements along the row; a view whose shadow leaves the detector does not certify.
// `certified` holds 1 per certified reading, [views][rows][n_u].
//
// Decided block by block: a view whose shadow of a whole block of voxels is certified (or
// holds no certified element) decides every voxel of the block at once, and only the views
// where a block's shadow is part certified test each voxel. The same decision as testing
// every voxel in every view (carve_each_voxel), which took most voxels inside an object
// through every view.
std::vector<std::uint8_t> carve_by_shadows(const Geometry& g, std::size_t rows,
                                           const std::vector<std::uint8_t>& certified,
                                           int min_views, double widen);

// The same, voxel by voxel over the views: the twin the tests hold carve_by_shadows to.
std::vector<std::uint8_t> carve_each_voxel(const Geometry& g, std::size_t rows,
                                           const std::vector<std::uint8_t>& certified,
                                           int min_views, double widen);

}  // namespace riner::model
