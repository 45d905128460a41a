#include "riner/slab_plan.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "riner/error.hpp"

namespace riner {

namespace {

// Measured with `riner_bench --case=slab_stack` (docs/history/RESULTS.md, "Issue 30"): at 1024
// columns x 720 views, a slab's peak resident memory is about 260 MB plus 24 MB per detector
// row (32 bytes per reading: the readings, their ray segments, the carving's and the quality
// check's filtered copies); the voxels count for little beside them.
constexpr double kReadingCopies = 8.0;
constexpr double kVoxelCopies = 12.0;
constexpr std::size_t kBaseBytes = std::size_t{260} << 20;  // model, kernels, libraries

// On a device (PoCL's buffers, counted as on a GPU; docs/history/RESULTS.md "device memory"): the
// model, the per-sample caches and the batch (95-256 MB measured), then per slice the quality
// check's FBP with its readings in two copies and the voxels (2048 columns x 1440 views: 26.4
// MB per slice against 32 MB here).
constexpr std::size_t kDeviceBaseBytes = std::size_t{256} << 20;
constexpr double kDeviceReadingCopies = 2.0;
constexpr double kDeviceVoxelCopies = 2.0;

double readings_per_slice(const Geometry& g) {
  return static_cast<double>(g.n_views()) * static_cast<double>(g.n_u) *
         static_cast<double>(g.n_v) / static_cast<double>(g.volume_shape[0]);
}

double voxels_per_slice(const Geometry& g) {
  return static_cast<double>(g.volume_shape[1]) * static_cast<double>(g.volume_shape[2]);
}

// The detector row (fractional index) a height z (mm) projects to in a parallel beam.
double row_at(const Geometry& g, double z_mm) {
  return z_mm / g.pitch_v + (static_cast<double>(g.n_v) - 1.0) / 2.0 - g.offset_v;
}

double slice_z(const Geometry& g, double k) {
  return (k - (static_cast<double>(g.volume_shape[0]) - 1.0) / 2.0) * g.voxel_mm;
}

}  // namespace

std::vector<Slab> plan_slabs(const Geometry& g, std::size_t slices_per_slab) {
  if (!g.is_3d()) throw InputError("slabs cut a volume: the geometry is 2D");
  const std::size_t nz = g.volume_shape[0];
  const std::size_t per = std::max<std::size_t>(1, std::min(slices_per_slab, nz));
  const std::size_t count = (nz + per - 1) / per;
  if (count > 1 && g.type != GeometryType::kParallel3d) {
    throw InputError(std::string("a ") + geometry_type_name(g.type) +
                     " scan is not cut into slabs (its rays cross slices): it needs memory for " +
                     "the whole volume; raise --memory-limit");
  }
  std::vector<Slab> slabs;
  for (std::size_t i = 0; i < count; ++i) {
    Slab s;
    s.index = i;
    s.first_slice = i * nz / count;
    s.slices = (i + 1) * nz / count - s.first_slice;
    if (g.type == GeometryType::kParallel3d) {
      // Rows whose centres lie in [bottom, top) of the slab's slices, in row order (the
      // detector's v runs along +z when pitch_v > 0).
      const double a = row_at(g, slice_z(g, static_cast<double>(s.first_slice) - 0.5));
      const double b = row_at(g, slice_z(g, static_cast<double>(s.first_slice + s.slices) - 0.5));
      const double lo = std::min(a, b), hi = std::max(a, b);
      const long first = std::max<long>(0, static_cast<long>(std::ceil(lo - 1e-9)));
      const long end = std::min<long>(static_cast<long>(g.n_v),
                                      static_cast<long>(std::ceil(hi - 1e-9)));
      if (end <= first) {
        throw InputError("slices " + std::to_string(s.first_slice) + ".." +
                         std::to_string(s.first_slice + s.slices) +
                         " project onto no detector row: use thicker slabs (the detector's " +
                         "rows are coarser than the voxels) or check the geometry");
      }
      s.rows = {static_cast<std::size_t>(first), static_cast<std::size_t>(end - first)};
    } else {
      s.rows = {0, g.n_v};
    }
    slabs.push_back(s);
  }
  return slabs;
}

Geometry slab_geometry(const Geometry& g, const Slab& slab) {
  Geometry s = detector_rows_geometry(g, slab.rows.first, slab.rows.count);
  if (slab.slices == g.volume_shape[0]) return s;
  s.volume_shape[0] = slab.slices;
  // The slab's grid is centred on the axis' origin; its detector rows move down by as much.
  const double shift_mm = slice_z(g, static_cast<double>(slab.first_slice) +
                                         (static_cast<double>(slab.slices) - 1.0) / 2.0);
  s.offset_v -= shift_mm / g.pitch_v;
  return s;
}

std::size_t slab_bytes(const Geometry& g, std::size_t slices) {
  const double per_slice =
      4.0 * (kReadingCopies * readings_per_slice(g) + kVoxelCopies * voxels_per_slice(g));
  return kBaseBytes + static_cast<std::size_t>(per_slice * static_cast<double>(slices));
}

std::size_t slab_device_bytes(const Geometry& g, std::size_t slices) {
  const double per_slice = 4.0 * (kDeviceReadingCopies * readings_per_slice(g) +
                                  kDeviceVoxelCopies * voxels_per_slice(g));
  return kDeviceBaseBytes + static_cast<std::size_t>(per_slice * static_cast<double>(slices));
}

std::size_t slab_largest_buffer_bytes(const Geometry& g, std::size_t slices) {
  return static_cast<std::size_t>(4.0 * readings_per_slice(g) * static_cast<double>(slices));
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
    out.slices_per_slab = std::max<std::size_t>(1, slices);
  }
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
  const std::string unit(end);
  if (unit == "K" || unit == "k" || unit == "KB" || unit == "KiB") scale = 1024.0;
  else if (unit == "M" || unit == "MB" || unit == "MiB") scale = 1024.0 * 1024.0;
  else if (unit == "G" || unit == "GB" || unit == "GiB") scale = 1024.0 * 1024.0 * 1024.0;
  else if (unit == "T" || unit == "TB" || unit == "TiB") scale = 1024.0 * 1024.0 * 1024.0 * 1024.0;
  else if (!unit.empty()) {
    throw InputError("a memory size is a number with an optional K, M, G or T (got '" + text +
                     "')");
  }
  return static_cast<std::size_t>(value * scale);
}

}  // namespace riner
