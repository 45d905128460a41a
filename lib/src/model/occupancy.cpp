#include "model/occupancy.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "model/air_readings.hpp"
#include "model/chessboard_distance.hpp"
#include "model/object_seen_by_fbp.hpp"
#include "model/shadow_carving.hpp"
#include "riner/array.hpp"
#include "riner/rays.hpp"
#include "util/parallel.hpp"

namespace riner::model {

namespace {

// The check's threshold grows with the rays it looks at so that noise alone crosses it on one
// ray in ten scans (5 sigma for 3e5 rays, 5.7 for the 1.2e7 of a 3D scan).
constexpr double kFalseAlarmsPerScan = 0.1;

// The z a normal exceeds with probability p (upper tail), by bisection.
double upper_quantile(double p) {
  double lo = 0.0, hi = 40.0;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (0.5 * std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return hi;
}

// The nearest integer of x >= -0.5, and some integer <= 0 below that (callers clamp to the
// grid): lround's result there without its call (9% of a 3D carving's time).
long nearest(double x) { return static_cast<long>(x + 0.5); }

// Rays' samples against a region, by the chessboard distance of each sample's voxel to it.
class RegionWalk {
 public:
  RegionWalk(const Geometry& g, const std::vector<std::uint8_t>& region)
      : distance_(chessboard_distance(region, g.volume_shape)) {
    const std::size_t rank = g.volume_shape.size();
    nx_ = static_cast<long>(g.volume_shape[rank - 1]);
    ny_ = static_cast<long>(g.volume_shape[rank - 2]);
    nz_ = rank == 3 ? static_cast<long>(g.volume_shape[0]) : 1;
    per_voxel_ = sampling_domain(g).extent_mm / g.voxel_mm;
  }

  // The voxel of sample k.
  std::size_t voxel_of(const RaySegment& s, std::uint32_t k) const {
    float pos[3];
    sample_position(s, k, 0.5f, pos);
    const double x = (pos[0] - 0.5) * per_voxel_, y = (pos[1] - 0.5) * per_voxel_,
                 z = (pos[2] - 0.5) * per_voxel_;
    const long column = std::clamp(nearest(x + 0.5 * (nx_ - 1)), 0L, nx_ - 1);
    const long row = std::clamp(nearest(0.5 * (ny_ - 1) - y), 0L, ny_ - 1);
    const long slice = nz_ > 1 ? std::clamp(nearest(z + 0.5 * (nz_ - 1)), 0L, nz_ - 1) : 0L;
    return static_cast<std::size_t>((slice * ny_ + row) * nx_ + column);
  }

  std::uint16_t distance(std::size_t voxel) const { return distance_[voxel]; }

  // The first and last samples inside the region; nullopt when none is.
  std::optional<std::pair<std::int64_t, std::int64_t>> kept_range(const RaySegment& s,
                                                                  double spacing_voxels) const {
    // Samples that can be stepped over from one at distance d: every voxel closer than d is
    // outside, and m samples move at most floor(m spacing) + 1 voxels.
    auto skip = [&](double d) {
      return std::max<std::int64_t>(
          1, static_cast<std::int64_t>(std::ceil((d - 1.0) / spacing_voxels)) - 1);
    };
    auto distance_at = [&](std::int64_t k) {
      return static_cast<double>(distance_[voxel_of(s, static_cast<std::uint32_t>(k))]);
    };
    std::int64_t first = 0;
    while (first < s.count) {
      const double d = distance_at(first);
      if (d == 0.0) break;
      first += skip(d);
    }
    if (first >= s.count) return std::nullopt;
    std::int64_t last = s.count - 1;
    while (last > first) {
      const double d = distance_at(last);
      if (d == 0.0) break;
      last -= skip(d);
    }
    return std::make_pair(first, std::max(last, first));
  }

 private:
  std::vector<std::uint16_t> distance_;
  long nx_ = 1, ny_ = 1, nz_ = 1;
  double per_voxel_ = 1.0;
};

struct RayCheck {
  double threshold = 0.0;  // noise sigmas
  std::size_t rays = 0;
  double excess = 0.0;
  double sigmas = 0.0;
  std::size_t above = 0;  // rays reading more than air
  std::size_t near = 0;   // of those, rays passing within `reach` voxels of the region
  double samples = 0.0;   // kept, over all rays
};

// Clips every ray to the region (its samples from the first to the last inside it; none when
// it misses) and, with `air`, runs step 4 on the rays that miss it: each must read air. One that
// reads more near the region says the carving took object; one far from it is a detector's
// spike or a separate faint object. One walk along each ray serves both.
RayCheck clip_and_check(RaySegments& segments, const Scan& scan,
                        const std::vector<std::uint8_t>& region, double spacing_voxels,
                        const AirReadings* air, double sigmas, int reach) {
  const RegionWalk walk(scan.geometry, region);
  RayCheck all;
  all.threshold = std::max(
      sigmas,
      upper_quantile(kFalseAlarmsPerScan / std::max(1.0, static_cast<double>(segments.size()))));
  std::vector<RayCheck> parts =
      util::parallel_map_chunks(segments.size(), [&](std::size_t begin, std::size_t end) {
        RayCheck part;
        for (std::size_t r = begin; r < end; ++r) {
          if (segments.count(r) == 0) continue;
          const RaySegment s = segments[r];
          const auto range = walk.kept_range(s, spacing_voxels);
          if (range) {
            const auto [first, last] = *range;
            const auto kept = static_cast<std::uint32_t>(last - first + 1);
            segments.clip(r, static_cast<std::uint32_t>(first), kept);
            part.samples += kept;
            continue;
          }
          const double z =
              air ? air->excess_sigmas(scan, r / air->per_view, r % air->per_view) : NAN;
          if (!std::isnan(z)) {
            ++part.rays;
            if (z > part.sigmas) {
              part.sigmas = z;
              part.excess = air->excess(scan, r / air->per_view, r % air->per_view);
            }
            if (z > all.threshold) {
              ++part.above;
              for (std::uint32_t k = 0; k < s.count; ++k) {
                if (walk.distance(walk.voxel_of(s, k)) <= reach) {
                  ++part.near;
                  break;
                }
              }
            }
          }
          segments.clip(r, 0, 0);
        }
        return part;
      });
  for (const RayCheck& p : parts) {
    all.rays += p.rays;
    all.above += p.above;
    all.near += p.near;
    all.samples += p.samples;
    if (p.sigmas > all.sigmas) {
      all.sigmas = p.sigmas;
      all.excess = p.excess;
    }
  }
  return all;
}

}  // namespace

OccupancySettings occupancy_settings(const TrainingConfig& training, const Geometry& g,
                                     Engine engine, std::optional<Device> device) {
  OccupancySettings s;
  s.noise_sigmas = training.air_noise_sigmas;
  s.margin_px = training.air_margin_px;
  s.min_views = training.air_min_views;
  s.centre_tolerance_px = training.air_centre_tolerance_px;
  s.fbp_check = training.air_fbp_check == AirFbpCheck::kOn ||
                (training.air_fbp_check == AirFbpCheck::kAuto && !g.is_3d());
  s.engine = engine;
  s.device = std::move(device);
  return s;
}

Occupancy carve_occupancy(const Scan& scan, RaySegments& segments, double spacing_voxels,
                          const OccupancySettings& settings) {
  const Geometry& g = scan.geometry;
  const std::size_t voxels = shape_size(g.volume_shape);
  Occupancy o;
  o.inside.assign(voxels, 1);
  const AirReadings air = read_air(scan, settings.noise_sigmas);
  o.air_elements = air.air_elements;
  o.air_offset_median = air.air_offset_median;
  o.noise = air.noise;
  o.outlier_views = air.outlier_views;
  if (!air.usable) {
    o.note = air.note;
    return o;
  }
  std::vector<std::uint8_t> kept = carve_by_shadows(
      g, g.is_3d() ? g.n_v : 1, air.certified(scan, settings.noise_sigmas),
      std::max(1, settings.min_views), std::max(0.0, settings.centre_tolerance_px));
  if (settings.fbp_check) {
    const ObjectSeenByFbp seen =
        object_seen_by_fbp(scan, kept, {settings.fbp_sigmas, settings.engine, settings.device});
    o.fbp_bin = seen.bin;
    o.fbp_noise = seen.noise;
    if (!seen.usable) {
      o.note = "too little air to check against the FBP (" + std::to_string(seen.air_voxels) +
               " binned voxels)";
      return o;
    }
    for (std::size_t i = 0; i < voxels; ++i) {
      o.kept_by_fbp += seen.object[i] && !kept[i];
      kept[i] = kept[i] || seen.object[i];
    }
  }
  const int margin = std::max(0, settings.margin_px);
  std::vector<std::uint8_t> region = dilated(kept, g.volume_shape, margin);
  const RayCheck check = clip_and_check(segments, scan, region, spacing_voxels, &air,
                                        settings.ray_check_sigmas, std::max(1, margin));
  o.samples_kept = check.samples;
  o.skipped_rays = check.rays;
  o.skipped_ray_excess = check.excess;
  o.skipped_ray_sigmas = check.sigmas;
  o.ray_check_threshold = check.threshold;
  o.skipped_rays_above = check.above;
  o.skipped_rays_near = check.near;
  std::size_t count = 0;
  for (std::uint8_t v : region) count += v;
  o.inside = std::move(region);
  o.carved = true;
  o.inside_fraction = static_cast<double>(count) / static_cast<double>(voxels);
  return o;
}

Occupancy carve_occupancy(const Scan& scan, const OccupancySettings& settings) {
  constexpr double kSpacingVoxels = 1.5;
  const Geometry& g = scan.geometry;
  RaySegments segments(g, kSpacingVoxels * g.voxel_mm, false);
  return carve_occupancy(scan, segments, kSpacingVoxels, settings);
}

void fade_into_skipped_air(const Occupancy& occupancy, const std::vector<std::size_t>& shape,
                           int taper_px, std::vector<float>& image) {
  if (!occupancy.carved) return;
  if (taper_px <= 0) {
    for (std::size_t i = 0; i < image.size(); ++i) {
      if (!occupancy.inside[i]) image[i] = 0.0f;
    }
    return;
  }
  // Depth of each voxel in the region: chessboard distance to the nearest voxel outside it
  // (1 on its outline, 0 outside).
  std::vector<std::uint8_t> outside(occupancy.inside.size());
  for (std::size_t i = 0; i < outside.size(); ++i) outside[i] = occupancy.inside[i] ? 0 : 1;
  const std::vector<std::uint16_t> depth = chessboard_distance(outside, shape);
  const double ramp = 1.0 / (taper_px + 1.0);
  for (std::size_t i = 0; i < image.size(); ++i) {
    if (depth[i] <= taper_px) image[i] = static_cast<float>(image[i] * depth[i] * ramp);
  }
}

double clip_segments(RaySegments& segments, const Scan& scan, const Occupancy& occupancy,
                     double spacing_voxels) {
  if (!occupancy.carved) {
    double samples = 0.0;
    for (std::size_t r = 0; r < segments.size(); ++r) samples += segments.count(r);
    return samples;
  }
  return clip_and_check(segments, scan, occupancy.inside, spacing_voxels, nullptr, 0.0, 0).samples;
}

}  // namespace riner::model
