// Chessboard distance (in voxels, 3^d - 1 neighbours) of every voxel of a 2D or 3D grid to the
// nearest marked one: how the air carving grows margins and steps rays over the air.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

namespace riner::model {

// Distances at or beyond this are stored as it (also: no voxel marked).
constexpr std::uint16_t kFarVoxels = std::numeric_limits<std::uint16_t>::max();

// Per voxel of `shape` (C order), its distance to the nearest voxel with marked != 0 (0 there).
std::vector<std::uint16_t> chessboard_distance(const std::vector<std::uint8_t>& marked,
                                               const std::vector<std::size_t>& shape);

// marked grown by `reach` voxels (chessboard): 1 within reach of a marked voxel.
std::vector<std::uint8_t> dilated(const std::vector<std::uint8_t>& marked,
                                  const std::vector<std::size_t>& shape, int reach);

}  // namespace riner::model
