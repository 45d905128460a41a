// Cutting a volume into slabs of axial slices, each trained alone on the detector rows its
// voxels project to: how a scan larger than memory (or than one device) goes through riner.
// In a parallel beam a row's rays stay in one slice, so slabs are independent. In a cone beam
// a row's rays climb through several slices: a slab trains its own slices and those around
// them that its rows' rays cross, on every row whose rays stay within them (so each reading is
// the sum of what the slab's field holds), and writes its own slices only.
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "riner/array.hpp"
#include "riner/geometry.hpp"

namespace riner {

struct Slab {
  std::size_t index = 0;
  std::size_t first_slice = 0;  // voxel slices [first_slice, first_slice + slices) it writes
  std::size_t slices = 0;
  // The detector rows it trains on: in a parallel beam those whose centres fall inside its
  // slices; in a cone beam every row whose rays, inside the reconstruction box, stay within
  // its trained slices (which holds every row that sees its own slices).
  RowRange rows;
  // The slices it trains: its own, and in a cone beam those around them its rows' rays cross.
  std::size_t trained_first = 0;
  std::size_t trained_slices = 0;
  // The rows whose response (alpha, beta) it gives the whole detector's maps: its rows in a
  // parallel beam; in a cone beam those whose centre ray crosses the axis within its own
  // slices (below the volume: the first slab's; above it: the last's).
  RowRange map_rows;
};

// Slabs of at most `slices_per_slab` slices covering the volume, as even as they come (64
// slices in slabs of 30: 22, 21, 21). InputError for a slab no detector row sees.
std::vector<Slab> plan_slabs(const Geometry& g, std::size_t slices_per_slab);

// The slab's own geometry: its rows of the detector and its trained slices of the volume. A
// parallel beam's grid is re-centred and the rows moved by as much along the axis; a cone
// beam's grid sits at the slices' height (Geometry::grid_centre_z_mm).
Geometry slab_geometry(const Geometry& g, const Slab& slab);

// The slab of `count` slices from `first` as plan_slabs would cut it (rows, trained slices).
Slab slab_extent(const Geometry& g, std::size_t first, std::size_t count);

// Host memory a slab of `slices` slices takes to train and check (measured, docs/history/RESULTS.md
// "Slabs"): a base for the model and the kernels, and per slice its share of the measurement
// and of the volume in the copies the training, the ring corrections and the quality check
// hold at once.
std::size_t slab_bytes(const Geometry& g, std::size_t slices);

// The same for the whole scan trained in one piece (not by slabs): every detector row is read,
// whatever rows the grid reaches.
std::size_t whole_run_bytes(const Geometry& g);

// Memory a slab of `slices` slices takes on a device with its own memory (a GPU; measured,
// docs/history/RESULTS.md "device memory"): the model and the training's per-sample caches, and per
// slice the quality check's FBP (its readings in two copies) and the voxels it evaluates.
std::size_t slab_device_bytes(const Geometry& g, std::size_t slices);
// The most slices a slab may hold within kMostElementsPerPiece readings and voxels (riner/
// geometry.hpp; at least 1). size_slabs cuts within it and refuses a slices_per_slab above it.
std::size_t slices_within_piece_size(const Geometry& g);
// InputError where slabs of `slices_per_slab` (0: as thin as need be) cannot stay within it:
// thicker than slices_within_piece_size, or a cone beam whose thinnest slab exceeds it.
// Returns slices_within_piece_size.
std::size_t check_slabs_within_piece_size(const Geometry& g, std::size_t slices_per_slab);
// InputError "slabs of N slices would hold more than ...: at most `most`" where `asked` (its
// slices a slab, the volume's at most) exceeds `most` (slices_within_piece_size, or FBP's).
void refuse_slabs_thicker_than(std::size_t asked, std::size_t most);
// The largest single device buffer of such a slab: one copy of its readings, or of its voxels
// (a cone-beam slab trains more slices than its rows).
std::size_t slab_largest_buffer_bytes(const Geometry& g, std::size_t slices);

// The most slices per slab within `limit` bytes (at least 1).
std::size_t slices_within(const Geometry& g, std::size_t limit);
// The same for any memory model: the most of `slices` whose bytes(n), rising with n, stay
// within `limit` (at least 1). Where bytes(n) also falls somewhere (a cone beam's cuts, the ray
// table given up past its size) the size returned still fits, though a larger one may too.
std::size_t most_slices_within(std::size_t slices, std::size_t limit,
                               const std::function<std::size_t(std::size_t)>& bytes);

// What bounds a run's slabs: the host's memory, shared by every slab the machine trains at once
// (all its processes'), and a device's own memory, shared by the slabs one process trains on it
// at once.
struct SlabMemory {
  std::size_t host_limit = 0;        // bytes
  std::size_t device_limit = 0;      // bytes; 0: the device works in host memory (a CPU)
  std::size_t device_max_alloc = 0;  // the device's largest buffer; 0: no bound
};

struct SlabSizing {
  std::size_t slices_per_slab = 1;
  int workers = 1;             // slabs one process trains at once
  bool device_bound = false;   // the device's memory, not the host's, cut the slabs or workers
};

// Slabs as thick as the memory allows with `wanted_workers` slabs trained at once by each of
// `processes` processes (fewer where not even one slice each fits), and no thicker than makes a
// slab for each; `slices_per_slab` when given (not 0). Then the workers the slabs' size leaves
// room for, at most the slabs there are.
SlabSizing size_slabs(const Geometry& g, const SlabMemory& memory, int wanted_workers,
                      int processes, std::size_t slices_per_slab = 0);

// Three quarters of the machine's physical memory: the default limit.
std::size_t default_memory_limit();

// "8G", "512M", "2.5G", "1000000" (bytes) -> bytes; InputError for anything else.
std::size_t parse_memory_size(const std::string& text);

}  // namespace riner
