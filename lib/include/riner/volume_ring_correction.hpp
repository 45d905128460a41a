// Ring corrections for parallel-beam volumes, slice by slice.
//
// In a parallel-beam scan each detector row's rays stay in one axial plane, so row r and the
// volume's slice at the same height are a 2D scan of their own: a per-element offset in row r
// of alpha is a ring in that slice and nothing else. The 2D corrections (riner/
// ring_correction.hpp: air, radial gradient, detector response) therefore apply to each such
// slice with its row of alpha, unchanged, each with its own evidence and gates. A cone beam has
// no such split (a row's rays cross many slices), so cone volumes are left as trained.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "riner/array.hpp"
#include "riner/geometry.hpp"
#include "riner/riner_config.hpp"

namespace riner {

struct VolumeRingCorrection {
  Array image;  // [n_z, n_y, n_x]
  Array alpha;  // [n_v, n_u]
  // Slices that had a detector row at their height (each corrected as a 2D scan), and of
  // those, how many each correction changed.
  std::size_t slices = 0;
  std::size_t air_applied = 0;
  std::size_t gradient_applied = 0;
  std::size_t gradient_after_response_applied = 0;
  std::size_t response_applied = 0;
  std::size_t mirror_applied = 0;
  // Mean |ln(alpha_new / alpha)| over the corrected rows' elements.
  double mean_response_change = 0.0;
  // Why nothing was done, when nothing was ("" otherwise).
  std::string note;
};

// The detector row whose rays lie in each slice's plane (parallel3d): -1 for a slice between
// rows or beyond the detector. Rows and slices coincide when the voxel equals the row pitch and
// the row offset is whole (or half, with the counts differing by one).
std::vector<long> rows_of_slices(const Geometry& geometry);

// `volume` on the 3D geometry's grid, `alpha` per detector pixel ([n_v, n_u]); `dead_elements`
// are flat indices into alpha (their alpha is not a response). Runs the corrections `config`
// turns on, in the 2D order, on every slice that has a row; returns the input with a note for
// a cone beam or when no slice has a row. `sampled`: per voxel, as correct_rings_in_order takes
// it per pixel, or empty. Throws InputError for a 2D geometry or mismatched shapes.
VolumeRingCorrection correct_rings_per_slice(const Array& volume, const Array& alpha,
                                             const Geometry& geometry,
                                             const std::vector<std::size_t>& dead_elements,
                                             const RingCorrectionConfig& config,
                                             const std::vector<std::uint8_t>& sampled = {});

}  // namespace riner
