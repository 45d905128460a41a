#include "riner/slab_fbp.hpp"

#include <algorithm>
#include <cmath>

#include "analytic/stopped_beam_rows.hpp"
#include "riner/error.hpp"
#include "riner/slab_plan.hpp"

namespace riner {

namespace {

// Fitted on `riner fbp --slab-slices 1|4|16` of a 720 x 32 x 1024 stack on PoCL (peaks of
// 227, 213 and 486 MB; docs/history/RESULTS.md, "FBP by slabs"): the OpenCL runtime's ~170 MB, the
// readings as read, normalised and filtered, the slab's voxels on the host and the device.
constexpr double kReadingCopies = 3.0;
constexpr double kVoxelCopies = 2.0;
constexpr std::size_t kBaseBytes = std::size_t{170} << 20;

std::size_t slab_count(std::size_t nz, std::size_t per) {
  per = std::max<std::size_t>(1, std::min(per, nz));
  return (nz + per - 1) / per;
}

}  // namespace

RowRange fbp_rows_reached(const Geometry& g, std::size_t first, std::size_t count) {
  const double nz = static_cast<double>(g.volume_shape[0]);
  const double z_lo = (static_cast<double>(first) - 0.5 - (nz - 1.0) / 2.0) * g.voxel_mm;
  const double z_hi = (static_cast<double>(first + count) - 0.5 - (nz - 1.0) / 2.0) * g.voxel_mm;
  // Magnifications from the nearest voxel to the source to the farthest.
  std::vector<double> scales = {1.0};
  if (g.type == GeometryType::kCone3d) {
    const double radius = 0.5 * g.voxel_mm *
                          std::hypot(static_cast<double>(g.volume_shape[1]),
                                     static_cast<double>(g.volume_shape[2]));
    if (radius >= g.source_origin_mm) return {0, g.n_v};  // the volume reaches the source
    scales = {(g.source_origin_mm + g.origin_detector_mm) / (g.source_origin_mm + radius),
              (g.source_origin_mm + g.origin_detector_mm) / (g.source_origin_mm - radius)};
  }
  double lo = INFINITY, hi = -INFINITY;
  for (double z : {z_lo, z_hi}) {
    for (double scale : scales) {
      const double v =
          z * scale / g.pitch_v + (static_cast<double>(g.n_v) - 1.0) / 2.0 - g.offset_v;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  // Bilinear sampling takes the row below and the row above a position.
  const double first_row = std::max(0.0, std::floor(lo) - 1.0);
  const double end_row = std::min(static_cast<double>(g.n_v), std::ceil(hi) + 2.0);
  if (!(end_row > first_row)) return {0, 0};
  return {static_cast<std::size_t>(first_row), static_cast<std::size_t>(end_row - first_row)};
}

namespace {

// What FBP of the first `slices` slices holds: the readings of the rows they reach (the
// outermost slab reaches the most rows in a cone beam) and their voxels.
struct SlabSize {
  double readings = 0.0;
  double voxels = 0.0;
};

SlabSize fbp_slab_size(const Geometry& g, std::size_t slices) {
  slices = std::min(slices, g.volume_shape[0]);
  const double rows = static_cast<double>(fbp_rows_reached(g, 0, slices).count);
  return {static_cast<double>(g.n_views()) * static_cast<double>(g.n_u) * rows,
          static_cast<double>(slices) * static_cast<double>(g.volume_shape[1]) *
              static_cast<double>(g.volume_shape[2])};
}

}  // namespace

std::size_t fbp_slab_bytes(const Geometry& g, std::size_t slices) {
  const SlabSize s = fbp_slab_size(g, slices);
  return kBaseBytes +
         static_cast<std::size_t>(4.0 * (kReadingCopies * s.readings + kVoxelCopies * s.voxels));
}

std::size_t fbp_slices_within(const Geometry& g, std::size_t limit) {
  return most_slices_within(g.volume_shape[0], limit,
                            [&](std::size_t n) { return fbp_slab_bytes(g, n); });
}

std::size_t fbp_slices_within_piece_size(const Geometry& g) {
  return most_slices_within(g.volume_shape[0], static_cast<std::size_t>(kMostElementsPerPiece),
                            [&](std::size_t n) {
                              const SlabSize s = fbp_slab_size(g, n);
                              return static_cast<std::size_t>(std::max(s.readings, s.voxels));
                            });
}

std::size_t fbp_slab_device_bytes(const Geometry& g, std::size_t slices) {
  const SlabSize s = fbp_slab_size(g, slices);
  return static_cast<std::size_t>(4.0 * (2.0 * s.readings + s.voxels));
}

std::size_t fbp_device_slices_within(const Geometry& g, std::size_t device_limit,
                                     std::size_t max_alloc) {
  const std::size_t nz = g.volume_shape[0];
  std::size_t slices = most_slices_within(
      nz, device_limit, [&](std::size_t n) { return fbp_slab_device_bytes(g, n); });
  if (max_alloc) {
    // Its largest buffer: the readings, or the volume.
    slices = std::min(slices, most_slices_within(nz, max_alloc, [&](std::size_t n) {
                        const SlabSize s = fbp_slab_size(g, n);
                        return static_cast<std::size_t>(4.0 * std::max(s.readings, s.voxels));
                      }));
  }
  return slices;
}

namespace {

// A slab's normalisation into the run's: its counts scaled to the rows no earlier slab read.
// Its invalid readings are the rows' non-finite ones after normalisation (`non_finite`).
void merge_flat_report(SlabFbpReport& report, const FlatFieldReport& slab, std::size_t new_rows,
                       std::size_t rows, std::size_t non_finite) {
  const double share = static_cast<double>(new_rows) / static_cast<double>(rows);
  const auto scaled = [&](std::size_t n) {
    return static_cast<std::size_t>(std::lround(share * static_cast<double>(n)));
  };
  if (!report.flat_field) {
    report.flat_field = slab;
    report.flat_field->invalid_readings = 0;
    report.flat_field->saturated_readings = 0;
    report.flat_field->readings_in_dark_noise = 0;
    report.flat_field->pixels_without_beam = 0;
    report.flat_field->pixels = 0;
  }
  FlatFieldReport& all = *report.flat_field;
  all.invalid_readings += non_finite;
  all.saturated_readings += scaled(slab.saturated_readings);
  all.readings_in_dark_noise += scaled(slab.readings_in_dark_noise);
  all.dark_noise = std::max(all.dark_noise, slab.dark_noise);
  all.pixels_without_beam += scaled(slab.pixels_without_beam);
  all.pixels += scaled(slab.pixels);
  if (std::isfinite(slab.air_first) && std::isfinite(slab.air_last) &&
      (!std::isfinite(all.air_first) || slab.air_drift_sigmas > all.air_drift_sigmas)) {
    all.air_first = slab.air_first;
    all.air_last = slab.air_last;
    all.air_drift_sigmas = slab.air_drift_sigmas;
  }
}

}  // namespace

SlabFbpReport fbp_by_slabs(const ScanRows& source, const FbpOptions& options, VolumeWriter& out,
                           std::size_t slices_per_slab,
                           const std::function<void(std::size_t, const Array&)>& written,
                           const std::function<void(Scan&)>& prepare) {
  const Geometry& g = source.geometry();
  if (options.slices.first != 0 || options.slices.step != 1 || options.slices.count != 0) {
    throw std::invalid_argument("fbp_by_slabs reconstructs every slice");
  }
  const std::size_t nz = g.volume_shape[0];
  refuse_slabs_thicker_than(std::min(slices_per_slab, nz), fbp_slices_within_piece_size(g));
  SlabFbpReport report;
  report.slabs = slab_count(nz, slices_per_slab);
  report.slices_per_slab = (nz + report.slabs - 1) / report.slabs;
  std::size_t counted_end = 0;  // rows before it were counted by an earlier slab
  for (std::size_t i = 0; i < report.slabs; ++i) {
    const std::size_t first = i * nz / report.slabs;
    const std::size_t count = (i + 1) * nz / report.slabs - first;
    const RowRange rows = fbp_rows_reached(g, first, count);
    Array slices({count, g.volume_shape[1], g.volume_shape[2]});  // 0 where no row reaches
    if (rows.count > 0) {
      // The rows in their place on the whole detector, the whole volume's grid: the slab's
      // slices selected from it sample exactly what the whole FBP's would.
      FlatFieldReport flat;
      Scan scan;
      try {
        scan = source.read(rows, &flat);
      } catch (const NoReadingsError&) {
        // Rows that read nothing (a dead row's slice): NaN, said, the rest of the volume goes on.
        std::fill(slices.data.begin(), slices.data.end(), NAN);
        report.slices_without_readings += count;
        out.write(first, slices);
        if (written) written(first, slices);
        continue;
      }
      const std::size_t new_first = std::max(rows.first, counted_end);
      const std::size_t new_rows = rows.end() > new_first ? rows.end() - new_first : 0;
      counted_end = std::max(counted_end, rows.end());
      std::size_t non_finite = 0;
      for (std::size_t v = 0; v < g.n_views(); ++v) {
        const float* line =
            scan.measurement.ptr() + (v * rows.count + (new_first - rows.first)) * g.n_u;
        for (std::size_t k = 0; k < new_rows * g.n_u; ++k) {
          non_finite += std::fabs(line[k]) <= kLargestReading ? 0 : 1;
        }
      }
      if (flat.flat_frames > 0) merge_flat_report(report, flat, new_rows, rows.count, non_finite);
      scan.geometry = detector_rows_geometry(g, rows.first, rows.count);
      if (prepare) prepare(scan);
      FbpOptions slab = options;
      slab.slices = {first, 1, count};
      // The stopped beam's readings on the rows no slab before read (a cone's slabs share rows).
      if (new_rows > 0) {
        Array fresh({g.n_views(), new_rows, g.n_u});
        for (std::size_t v = 0; v < g.n_views(); ++v) {
          std::copy_n(scan.measurement.ptr() + (v * rows.count + (new_first - rows.first)) * g.n_u,
                      new_rows * g.n_u, fresh.ptr() + v * new_rows * g.n_u);
        }
        const std::size_t stopped = analytic::stopped_beam_rows(fresh, g, false).count;
        report.fbp.stopped_beam_readings += stopped;
        // Read at the floor, not interpolated.
        if (options.stopped_beam_at_floor) non_finite -= std::min(non_finite, stopped);
      }
      report.fbp.non_finite_replaced += non_finite;
      slab.count_stopped_beam = false;  // counted above, once per row
      FbpReport part;
      slices = fbp(scan, slab, &part);
      report.fbp.short_scan = report.fbp.short_scan || part.short_scan;
      report.fbp.parker_weighted = report.fbp.parker_weighted || part.parker_weighted;
      report.fbp.half_acquisition_overlap_mm = part.half_acquisition_overlap_mm;
      report.fbp.stopped_beam_floor =
          std::max(report.fbp.stopped_beam_floor, part.stopped_beam_floor);
    }
    out.write(first, slices);
    if (written) written(first, slices);
  }
  return report;
}

}  // namespace riner
