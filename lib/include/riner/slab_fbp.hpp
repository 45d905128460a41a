// FBP (parallel beam) or FDK (cone beam) of a projection stack slab by slab: each slab of axial
// slices reads alone (riner/scan_source.hpp) the detector rows its voxels reach, found from the
// geometry (a cone beam's spread by the magnification from the nearest voxel to the farthest),
// filters and backprojects them, and hands its slices to a VolumeWriter, so a stack larger
// than memory goes through in the memory of one slab. Filtering is row by row and the
// backprojection voxel by voxel, so each slice is the whole volume's (to float rounding; a test
// checks both beams).
#pragma once

#include <cstddef>
#include <functional>
#include <optional>

#include "riner/fbp.hpp"
#include "riner/scan_source.hpp"
#include "riner/volume_writer.hpp"

namespace riner {

struct SlabFbpReport {
  std::size_t slabs = 0;
  std::size_t slices_per_slab = 0;
  FbpReport fbp;  // summed over the slabs (each detector row's readings counted once)
  // Raw projections' normalisation over the slabs: counts of each row once, the drift of the
  // slab where the air moved most.
  std::optional<FlatFieldReport> flat_field;
  // Slices of slabs whose rows read nothing to reconstruct (all NaN): written as NaN.
  std::size_t slices_without_readings = 0;
};

// The detector rows slices [first, first + count) of g's volume project to, with the row
// either side that bilinear sampling takes; count 0 when none.
RowRange fbp_rows_reached(const Geometry& g, std::size_t first, std::size_t count);

// Host memory FBP of a slab of `slices` slices takes (measured, docs/history/RESULTS.md "FBP by
// slabs"): a base for the runtime and the kernels, the slab's readings in their copies (read,
// normalised, filtered) and its voxels.
std::size_t fbp_slab_bytes(const Geometry& g, std::size_t slices);
// The most slices per slab within `limit` bytes (at least 1).
std::size_t fbp_slices_within(const Geometry& g, std::size_t limit);
// The most slices an FBP slab may hold within kMostElementsPerPiece readings and voxels
// (riner/geometry.hpp; at least 1); fbp_by_slabs refuses thicker slabs.
std::size_t fbp_slices_within_piece_size(const Geometry& g);
// Memory FBP of a slab takes on a device with its own (a GPU): its readings in two copies
// (weighted, filtered) and its voxels.
std::size_t fbp_slab_device_bytes(const Geometry& g, std::size_t slices);
// The most slices per slab whose FBP fits `device_limit` bytes of a device's memory with no
// buffer over `max_alloc` (0: no bound); at least 1.
std::size_t fbp_device_slices_within(const Geometry& g, std::size_t device_limit,
                                     std::size_t max_alloc);

// Every slice of `source`'s volume into `out` (not closed), slabs of `slices_per_slab` in
// order (slabs as even as they come); `written` after each slab with its first slice and its
// slices; `prepare` on each slab's rows before their FBP (a stripe filter, say: rows are
// independent sinograms). InputError as ScanRows::read; options.slices must select every slice
// (the default).
SlabFbpReport fbp_by_slabs(const ScanRows& source, const FbpOptions& options, VolumeWriter& out,
                           std::size_t slices_per_slab,
                           const std::function<void(std::size_t first_slice, const Array& slices)>&
                               written = {},
                           const std::function<void(Scan& rows)>& prepare = {});

}  // namespace riner
