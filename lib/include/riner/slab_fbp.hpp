// FBP of a parallel-beam projection stack slab by slab (riner/slab_plan.hpp): each slab's
// detector rows, and one more on either side (its slices' backprojection interpolates between
// rows), are read alone (riner/scan_source.hpp), filtered, backprojected and handed to a
// VolumeWriter, so a stack larger than memory goes through FBP in the memory of one slab. Each
// slice is the whole volume's FBP slice (to float rounding; a test checks).
#pragma once

#include <cstddef>
#include <functional>

#include "riner/fbp.hpp"
#include "riner/scan_source.hpp"
#include "riner/volume_writer.hpp"

namespace riner {

struct SlabFbpReport {
  std::size_t slabs = 0;
  std::size_t slices_per_slab = 0;
  FbpReport fbp;  // summed over the slabs
};

// Host memory FBP of a slab of `slices` slices takes (measured, bench/RESULTS.md "FBP by
// slabs"): a base for the runtime and the kernels, the slab's readings in their copies (read,
// normalised, filtered) and its voxels.
std::size_t fbp_slab_bytes(const Geometry& g, std::size_t slices);
// The most slices per slab within `limit` bytes (at least 1).
std::size_t fbp_slices_within(const Geometry& g, std::size_t limit);

// Every slice of `source`'s volume into `out` (not closed), slabs of `slices_per_slab` in
// order; `written` after each slab with its first slice and its slices. InputError as ScanRows::read
// and plan_slabs; options.slices must select every slice (the default).
SlabFbpReport fbp_by_slabs(const ScanRows& source, const FbpOptions& options, VolumeWriter& out,
                           std::size_t slices_per_slab,
                           const std::function<void(std::size_t first_slice, const Array& slices)>&
                               written = {});

}  // namespace riner
