#include "riner/slab_plan.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <utility>

#include "model/ray_segments.hpp"
#include "riner/error.hpp"
#include "riner/rays.hpp"

namespace riner {

namespace {

// Measured (docs/history/RESULTS.md, "Issue 30: a volume's rays computed when drawn"): a slab's
// peak resident memory is about 260 MB (PoCL, the kernels, the model) plus, per reading, its ray
// segment (RaySegments: 32 bytes in a table, 8 past the table's size) and 4-5 float copies (the
// readings in the scan and in training, the detail's residual and halves), plus 6 per voxel.
// Fitted on a parallel slab of 720 x 8 x 1024 readings (582 MB measured, the segments tabled)
// and cone-beam slabs and volumes of the chest CT (548-863 MB, the segments computed).
constexpr double kReadingCopies = 5.0;
constexpr double kVoxelCopies = 6.0;
constexpr std::size_t kBaseBytes = std::size_t{260} << 20;  // model, kernels, libraries

// On a device (PoCL's buffers, counted as on a GPU; docs/history/RESULTS.md "device memory"): the
// model, the per-sample caches and the batch (95-256 MB measured), then per slice the quality
// check's FBP with its readings in two copies and the voxels (2048 columns x 1440 views: 26.4
// MB per slice against 32 MB here). The ray segments stay on the host.
constexpr std::size_t kDeviceBaseBytes = std::size_t{256} << 20;
constexpr double kDeviceReadingCopies = 2.0;
constexpr double kDeviceVoxelCopies = 2.0;

double voxels_per_slice(const Geometry& g) {
  return static_cast<double>(g.volume_shape[1]) * static_cast<double>(g.volume_shape[2]);
}

// The detector row (fractional index) a height z (mm) projects to in a parallel beam.
double row_at(const Geometry& g, double z_mm) {
  return z_mm / g.pitch_v + (static_cast<double>(g.n_v) - 1.0) / 2.0 - g.offset_v;
}

// The height of slice k's centre (fractional k: its edges at k -+ 0.5) in the grid's frame.
double slice_z(const Geometry& g, double k) {
  return (k - (static_cast<double>(g.volume_shape[0]) - 1.0) / 2.0) * g.voxel_mm;
}

Slab parallel_slab(const Geometry& g, std::size_t first, std::size_t count) {
  Slab s;
  s.first_slice = s.trained_first = first;
  s.slices = s.trained_slices = count;
  // Rows whose centres lie in [bottom, top) of the slab's slices, in row order (the detector's
  // v runs along +z when pitch_v > 0).
  const double a = row_at(g, slice_z(g, static_cast<double>(first) - 0.5) + g.grid_centre_z_mm);
  const double b =
      row_at(g, slice_z(g, static_cast<double>(first + count) - 0.5) + g.grid_centre_z_mm);
  const double lo = std::min(a, b), hi = std::max(a, b);
  const long begin = std::max<long>(0, static_cast<long>(std::ceil(lo - 1e-9)));
  const long end =
      std::min<long>(static_cast<long>(g.n_v), static_cast<long>(std::ceil(hi - 1e-9)));
  if (end > begin) {
    s.rows = {static_cast<std::size_t>(begin), static_cast<std::size_t>(end - begin)};
  }
  s.map_rows = s.rows;
  return s;
}

// A cone beam's slab. Heights are in the scan's frame (0 at the source's plane). A ray of a row
// at v mm on the detector is at height v (SOD + b) / SDD at depth b towards the detector, and
// the reconstruction box holds depths within its half-diagonal R of the axis: so a row's rays
// inside the box stay between v (SOD - R) / SDD and v (SOD + R) / SDD, whatever the view and
// the column.
Slab cone_slab(const Geometry& g, std::size_t first, std::size_t count) {
  const std::size_t nz = g.volume_shape[0];
  const double sdd = g.source_origin_mm + g.origin_detector_mm;
  const double reach =
      0.5 * g.voxel_mm *
      std::hypot(static_cast<double>(g.volume_shape[1]), static_cast<double>(g.volume_shape[2]));
  const double near = (g.source_origin_mm - reach) / sdd;  // > 0: validate() keeps the source out
  const double far = (g.source_origin_mm + reach) / sdd;
  const double box_low = slice_z(g, -0.5) + g.grid_centre_z_mm;
  const double box_high = slice_z(g, static_cast<double>(nz) - 0.5) + g.grid_centre_z_mm;
  // The heights a row's rays cross inside the box (a whole element: its lower and upper edges);
  // a row whose rays miss the box keeps the box's nearer face.
  auto heights = [&](std::size_t row) {
    const double a = detector_row_mm(g, static_cast<double>(row) - 0.5);
    const double b = detector_row_mm(g, static_cast<double>(row) + 0.5);
    const double low = std::min(a * near, a * far), high = std::max(b * near, b * far);
    return std::pair{std::clamp(low, box_low, box_high), std::clamp(high, box_low, box_high)};
  };
  const double own_low = slice_z(g, static_cast<double>(first) - 0.5) + g.grid_centre_z_mm;
  const double own_high = slice_z(g, static_cast<double>(first + count) - 0.5) + g.grid_centre_z_mm;
  // Every row that sees the slab's own slices, and the heights their rays cross.
  double low = own_low, high = own_high;
  bool seen = false;
  for (std::size_t r = 0; r < g.n_v; ++r) {
    const auto [lo, hi] = heights(r);
    if (hi < own_low || lo > own_high || !(hi > lo)) continue;
    seen = true;
    low = std::min(low, lo);
    high = std::max(high, hi);
  }
  Slab s;
  s.first_slice = first;
  s.slices = count;
  if (!seen) return s;
  // Whole slices around them, and every row whose rays stay within those.
  const double voxel = g.voxel_mm;
  s.trained_first =
      static_cast<std::size_t>(std::max(0.0, std::floor((low - box_low) / voxel + 1e-9)));
  const auto trained_end = static_cast<std::size_t>(
      std::min(static_cast<double>(nz), std::ceil((high - box_low) / voxel - 1e-9)));
  s.trained_slices = trained_end - s.trained_first;
  const double trained_low = box_low + static_cast<double>(s.trained_first) * voxel;
  const double trained_high = box_low + static_cast<double>(trained_end) * voxel;
  const double slack = 1e-9 * voxel;
  std::size_t begin = g.n_v, end = 0;
  for (std::size_t r = 0; r < g.n_v; ++r) {
    const auto [lo, hi] = heights(r);
    if (lo < trained_low - slack || hi > trained_high + slack) continue;
    begin = std::min(begin, r);
    end = r + 1;
  }
  s.rows = {begin, end - begin};
  // The rows whose centre ray crosses the axis in the slab's own slices.
  const bool bottom = first == 0, top = first + count == nz;
  std::size_t map_begin = end, map_end = begin;
  for (std::size_t r = begin; r < end; ++r) {
    const double axis = detector_row_mm(g, static_cast<double>(r)) * g.source_origin_mm / sdd;
    if ((axis < own_low && !bottom) || (axis >= own_high && !top)) continue;
    map_begin = std::min(map_begin, r);
    map_end = r + 1;
  }
  if (map_end > map_begin) s.map_rows = {map_begin, map_end - map_begin};
  return s;
}

// Where slabs of at most `per` slices cut the volume: [first, count) each, as even as they
// come. A cone beam is cut at the source's plane first (when it crosses the volume): a row
// above the plane climbs upwards across the object and a row below it downwards, so a slab
// across the plane would train the slices both ways (at a wide cone, the whole volume).
std::vector<std::pair<std::size_t, std::size_t>> slab_cuts(const Geometry& g, std::size_t per) {
  const std::size_t nz = g.volume_shape[0];
  per = std::max<std::size_t>(1, std::min(per, nz));
  std::vector<std::pair<std::size_t, std::size_t>> cuts;
  auto even = [&](std::size_t from, std::size_t slices) {
    const std::size_t count = (slices + per - 1) / per;
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t first = i * slices / count;
      cuts.emplace_back(from + first, (i + 1) * slices / count - first);
    }
  };
  std::size_t plane = 0;
  if (g.type == GeometryType::kCone3d && per < nz) {
    // The slice edge nearest the source's plane (height 0).
    const double edge = std::round(-(slice_z(g, -0.5) + g.grid_centre_z_mm) / g.voxel_mm);
    if (edge > 0.0 && edge < static_cast<double>(nz)) plane = static_cast<std::size_t>(edge);
  }
  if (plane == 0) {
    even(0, nz);
  } else {
    even(0, plane);
    even(plane, nz - plane);
  }
  return cuts;
}

// The readings and voxels a slab of `slices` slices holds at most: the outermost slab's in a
// cone beam (it crosses the most slices beside its own), a share of the detector otherwise.
struct SlabSize {
  double readings = 0.0;
  double voxels = 0.0;
};

SlabSize slab_size(const Geometry& g, std::size_t slices) {
  const std::size_t nz = g.volume_shape[0];
  slices = std::max<std::size_t>(1, std::min(slices, nz));
  const double per_row = static_cast<double>(g.n_views()) * static_cast<double>(g.n_u);
  if (g.type != GeometryType::kCone3d) {
    // The rows whose centres fall within the slices' height, wherever the grid sits on the
    // detector (a grid shorter than the detector reaches only its share of the rows).
    const double rows =
        std::min(static_cast<double>(g.n_v),
                 std::ceil(static_cast<double>(slices) * g.voxel_mm / std::fabs(g.pitch_v) - 1e-9));
    return {per_row * rows, voxels_per_slice(g) * static_cast<double>(slices)};
  }
  if (slices == nz) {
    return {per_row * static_cast<double>(g.n_v), voxels_per_slice(g) * static_cast<double>(nz)};
  }
  SlabSize most;
  for (const auto& [first, count] : slab_cuts(g, slices)) {
    const Slab s = cone_slab(g, first, count);
    most.readings = std::max(most.readings, per_row * static_cast<double>(s.rows.count));
    most.voxels =
        std::max(most.voxels, voxels_per_slice(g) * static_cast<double>(s.trained_slices));
  }
  return most;
}

}  // namespace

Slab slab_extent(const Geometry& g, std::size_t first, std::size_t count) {
  if (g.type != GeometryType::kCone3d) return parallel_slab(g, first, count);
  if (first == 0 && count == g.volume_shape[0]) {  // the whole volume, on the whole detector
    Slab s;
    s.slices = s.trained_slices = count;
    s.rows = s.map_rows = {0, g.n_v};
    return s;
  }
  return cone_slab(g, first, count);
}

std::vector<Slab> plan_slabs(const Geometry& g, std::size_t slices_per_slab) {
  if (!g.is_3d()) throw InputError("slabs cut a volume: the geometry is 2D");
  std::vector<Slab> slabs;
  for (const auto& [first, count] : slab_cuts(g, slices_per_slab)) {
    Slab s = slab_extent(g, first, count);
    s.index = slabs.size();
    if (s.rows.count == 0) {
      throw InputError("slices " + std::to_string(s.first_slice) + ".." +
                       std::to_string(s.first_slice + s.slices) +
                       " project onto no detector row: use thicker slabs (the detector's " +
                       "rows are coarser than the voxels) or check the geometry");
    }
    slabs.push_back(s);
  }
  return slabs;
}

Geometry slab_geometry(const Geometry& g, const Slab& slab) {
  Geometry s = detector_rows_geometry(g, slab.rows.first, slab.rows.count);
  if (slab.trained_slices == g.volume_shape[0]) return s;
  s.volume_shape[0] = slab.trained_slices;
  const double centre = slice_z(g, static_cast<double>(slab.trained_first) +
                                       (static_cast<double>(slab.trained_slices) - 1.0) / 2.0);
  if (g.type == GeometryType::kCone3d) {
    // A cone's rays do not move with the detector: the grid goes to the slices' height.
    s.grid_centre_z_mm = g.grid_centre_z_mm + centre;
  } else {
    // The slab's grid is centred on the axis' origin; its detector rows move down by as much.
    s.offset_v -= centre / g.pitch_v;
  }
  return s;
}

namespace {

std::size_t bytes_of(const SlabSize& size) {
  return kBaseBytes +
         static_cast<std::size_t>(4.0 *
                                  (kReadingCopies * size.readings + kVoxelCopies * size.voxels)) +
         // Falls past the table's size; most_slices_within still gives a size that fits (it
         // keeps only sizes found within the limit), at worst not the largest.
         model::RaySegments::held_bytes(static_cast<std::size_t>(size.readings));
}

}  // namespace

std::size_t slab_bytes(const Geometry& g, std::size_t slices) {
  return bytes_of(slab_size(g, slices));
}

std::size_t whole_run_bytes(const Geometry& g) {
  return bytes_of({reading_count(g), voxel_count(g)});
}

std::size_t slab_device_bytes(const Geometry& g, std::size_t slices) {
  const SlabSize size = slab_size(g, slices);
  return kDeviceBaseBytes + static_cast<std::size_t>(4.0 * (kDeviceReadingCopies * size.readings +
                                                            kDeviceVoxelCopies * size.voxels));
}

std::size_t slices_within_piece_size(const Geometry& g) {
  return most_slices_within(g.volume_shape[0], static_cast<std::size_t>(kMostElementsPerPiece),
                            [&](std::size_t n) {
                              const SlabSize size = slab_size(g, n);
                              return static_cast<std::size_t>(std::max(size.readings, size.voxels));
                            });
}

namespace {

// A cone beam's thinnest slab still trains every slice its rows' rays cross.
void refuse_slab_over_piece_size(const Geometry& g, std::size_t slices) {
  const SlabSize size = slab_size(g, slices);
  if (std::max(size.readings, size.voxels) <= kMostElementsPerPiece) return;
  char line[400];
  std::snprintf(line, sizeof(line),
                "a slab of %zu slice(s) of this scan holds %.4g readings and %.4g voxels (the "
                "slices its rows' rays cross), more than the 2^31 - 1 one piece of work may "
                "hold (the kernels' 32-bit indices): use larger voxels or a smaller volume",
                slices, size.readings, size.voxels);
  throw InputError(line);
}

}  // namespace

void refuse_slabs_thicker_than(std::size_t asked, std::size_t most) {
  if (asked <= most) return;
  throw InputError("slabs of " + std::to_string(asked) +
                   " slices would hold more than the 2^31 - 1 readings or voxels one piece of "
                   "work may hold (the kernels' 32-bit indices): at most " +
                   std::to_string(most) + " slices a slab for this scan");
}

std::size_t check_slabs_within_piece_size(const Geometry& g, std::size_t slices_per_slab) {
  const std::size_t most = slices_within_piece_size(g);
  refuse_slabs_thicker_than(std::min(slices_per_slab, g.volume_shape[0]), most);
  refuse_slab_over_piece_size(g, most);
  return most;
}

std::size_t slab_largest_buffer_bytes(const Geometry& g, std::size_t slices) {
  const SlabSize size = slab_size(g, slices);
  return static_cast<std::size_t>(4.0 * std::max(size.readings, size.voxels));
}

SlabSizing size_slabs(const Geometry& g, const SlabMemory& memory, int wanted_workers,
                      int processes, std::size_t slices_per_slab) {
  const std::size_t nz = g.volume_shape[0];
  wanted_workers = std::max(1, wanted_workers);
  processes = std::max(1, processes);
  const bool device = memory.device_limit > 0;
  // How many slabs of `slices` fit at once in each memory.
  auto host_fit = [&](std::size_t slices) {
    return static_cast<int>(std::max<std::size_t>(1, memory.host_limit / slab_bytes(g, slices)));
  };
  auto device_fit = [&](std::size_t slices) {
    if (!device) return wanted_workers;
    return static_cast<int>(
        std::max<std::size_t>(1, memory.device_limit / slab_device_bytes(g, slices)));
  };
  SlabSizing out;
  const std::size_t most = check_slabs_within_piece_size(g, slices_per_slab);
  if (slices_per_slab) {
    out.slices_per_slab = std::min(slices_per_slab, nz);
  } else {
    // The slabs trained at once share each limit, and each gets a slab to train.
    const int on_host = std::min(wanted_workers * processes, host_fit(1));
    const int on_device = std::min(wanted_workers, device_fit(1));
    std::size_t slices =
        std::min(slices_within(g, memory.host_limit / static_cast<std::size_t>(on_host)),
                 (nz + static_cast<std::size_t>(on_host) - 1) / static_cast<std::size_t>(on_host));
    if (device) {
      const std::size_t share = memory.device_limit / static_cast<std::size_t>(on_device);
      std::size_t on_gpu = most_slices_within(
          nz, share, [&](std::size_t n) { return slab_device_bytes(g, n); });
      if (memory.device_max_alloc) {
        on_gpu = std::min(on_gpu, most_slices_within(nz, memory.device_max_alloc,
                                                     [&](std::size_t n) {
                                                       return slab_largest_buffer_bytes(g, n);
                                                     }));
      }
      out.device_bound = on_gpu < slices;
      slices = std::min(slices, on_gpu);
    }
    out.slices_per_slab = std::max<std::size_t>(1, std::min(slices, most));
  }
  refuse_slab_over_piece_size(g, out.slices_per_slab);
  const std::size_t slabs = (nz + out.slices_per_slab - 1) / out.slices_per_slab;
  const int by_host = host_fit(out.slices_per_slab) / processes;
  const int by_device = device_fit(out.slices_per_slab);
  out.device_bound = out.device_bound || (device && by_device < std::min(wanted_workers, by_host));
  out.workers = std::max(1, std::min({wanted_workers, by_host, by_device,
                                      static_cast<int>(std::min<std::size_t>(slabs, 1 << 20))}));
  return out;
}

std::size_t most_slices_within(std::size_t slices, std::size_t limit,
                               const std::function<std::size_t(std::size_t)>& bytes) {
  std::size_t lo = 1, hi = slices;
  if (bytes(hi) <= limit) return hi;
  while (hi - lo > 1) {
    const std::size_t mid = (lo + hi) / 2;
    (bytes(mid) <= limit ? lo : hi) = mid;
  }
  return lo;
}

std::size_t slices_within(const Geometry& g, std::size_t limit) {
  return most_slices_within(g.volume_shape[0], limit,
                            [&](std::size_t n) { return slab_bytes(g, n); });
}

std::size_t default_memory_limit() {
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long page = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || page <= 0) return std::size_t{8} << 30;
  return static_cast<std::size_t>(pages) * static_cast<std::size_t>(page) / 4 * 3;
}

std::size_t parse_memory_size(const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || !(value > 0.0) || !std::isfinite(value)) {
    throw InputError("a memory size is a number with an optional K, M, G or T (got '" + text +
                     "')");
  }
  double scale = 1.0;
  std::string unit(end);
  // 8g and 512m as well as 8G and 512M (sizes are binary either way).
  std::transform(unit.begin(), unit.end(), unit.begin(),
                 [](unsigned char c) { return static_cast<char>(std::toupper(c)); });
  if (unit == "K" || unit == "KB" || unit == "KIB")
    scale = 1024.0;
  else if (unit == "M" || unit == "MB" || unit == "MIB")
    scale = 1024.0 * 1024.0;
  else if (unit == "G" || unit == "GB" || unit == "GIB")
    scale = 1024.0 * 1024.0 * 1024.0;
  else if (unit == "T" || unit == "TB" || unit == "TIB")
    scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
  else if (!unit.empty()) {
    throw InputError("a memory size is a number with an optional K, M, G or T (got '" + text +
                     "')");
  }
  // Less than a mebibyte holds no slab, and beyond an exbibyte is no machine's: a unit's slip.
  const double bytes = value * scale;
  if (bytes < 1024.0 * 1024.0 || bytes > 1152921504606846976.0) {
    throw InputError("a memory size is 1M to 1024P (got '" + text + "')");
  }
  return static_cast<std::size_t>(bytes);
}

}  // namespace riner
