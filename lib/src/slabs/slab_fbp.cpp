#include "riner/slab_fbp.hpp"

#include <algorithm>

#include "riner/error.hpp"
#include "riner/slab_plan.hpp"

namespace riner {

namespace {

// Fitted on `riner fbp --slab-slices 1|4|16` of a 720 x 32 x 1024 stack on PoCL (peaks of
// 227, 213 and 486 MB; bench/RESULTS.md, "FBP by slabs"): the OpenCL runtime's ~170 MB, the
// readings as read, normalised and filtered, the slab's voxels on the host and the device.
constexpr double kReadingCopies = 3.0;
constexpr double kVoxelCopies = 2.0;
constexpr std::size_t kBaseBytes = std::size_t{170} << 20;

}  // namespace

std::size_t fbp_slab_bytes(const Geometry& g, std::size_t slices) {
  const double nz = static_cast<double>(g.volume_shape[0]);
  const double rows = std::min(static_cast<double>(g.n_v),
                               static_cast<double>(g.n_v) / nz * static_cast<double>(slices) + 2.0);
  const double readings = static_cast<double>(g.n_views()) * static_cast<double>(g.n_u) * rows;
  const double voxels = static_cast<double>(slices) * static_cast<double>(g.volume_shape[1]) *
                        static_cast<double>(g.volume_shape[2]);
  return kBaseBytes +
         static_cast<std::size_t>(4.0 * (kReadingCopies * readings + kVoxelCopies * voxels));
}

std::size_t fbp_slices_within(const Geometry& g, std::size_t limit) {
  std::size_t lo = 1, hi = g.volume_shape[0];
  if (fbp_slab_bytes(g, hi) <= limit) return hi;
  while (hi - lo > 1) {
    const std::size_t mid = (lo + hi) / 2;
    (fbp_slab_bytes(g, mid) <= limit ? lo : hi) = mid;
  }
  return lo;
}

SlabFbpReport fbp_by_slabs(const ScanRows& source, const FbpOptions& options, VolumeWriter& out,
                           std::size_t slices_per_slab,
                           const std::function<void(std::size_t, const Array&)>& written) {
  const Geometry& g = source.geometry();
  if (options.slices.first != 0 || options.slices.step != 1 || options.slices.count != 0) {
    throw std::invalid_argument("fbp_by_slabs reconstructs every slice");
  }
  SlabFbpReport report;
  const std::vector<Slab> slabs = plan_slabs(g, slices_per_slab);
  report.slabs = slabs.size();
  report.slices_per_slab = std::min(slices_per_slab, g.volume_shape[0]);
  for (Slab slab : slabs) {
    // One row more on either side: a slice between two rows takes both.
    const std::size_t first = slab.rows.first > 0 ? slab.rows.first - 1 : 0;
    const std::size_t end = std::min(g.n_v, slab.rows.first + slab.rows.count + 1);
    slab.rows = {first, end - first};
    Scan scan = source.read(slab.rows);
    scan.geometry = slab_geometry(g, slab);
    FbpReport part;
    const Array slices = fbp(scan, options, &part);
    report.fbp.non_finite_replaced += part.non_finite_replaced;
    report.fbp.short_scan = report.fbp.short_scan || part.short_scan;
    out.write(slab.first_slice, slices);
    if (written) written(slab.first_slice, slices);
  }
  return report;
}

}  // namespace riner
