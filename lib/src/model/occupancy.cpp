#include "model/occupancy.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "riner/array.hpp"
#include "riner/rays.hpp"
#include "util/parallel.hpp"

namespace riner::model {

namespace {

// Spread of an element's readings: the interquartile range of a normal is 1.349 sigma.
constexpr double kIqrPerSigma = 1.349;
// An element reads air in every view when its spread is close to the quietest elements' and
// nothing sticks out (the range of 360 normal samples is about 6 sigma).
constexpr double kAirSpreadFactor = 2.0;
constexpr double kAirRangeSigmas = 12.0;
// An air reading is -ln alpha: a detector whose responses are within [0.6, 1.65] of the flat
// field. Steadier, larger readings are an object centred on the axis that every view shows
// alike (wider than the detector, say), not air.
constexpr double kMaxAirOffset = 0.5;
// Normalised by a flat field, air reads about 0 on average (-ln of responses around 1; the
// shared scans: -0.001 to 0.04). Steady readings that average more are an object centred on
// the axis, or a scan normalised by the wrong I0: no carving.
constexpr double kMaxAirLevel = 0.1;
// Fewer air elements than this: no trustworthy noise or offset range, so no carving.
constexpr std::size_t kMinAirElements = 4;
// Noise floor (rho units) for noise-free simulations.
constexpr double kNoiseFloor = 1e-5;
constexpr std::uint16_t kFar = std::numeric_limits<std::uint16_t>::max();

struct ElementStats {
  std::size_t finite = 0;
  double min = 0.0;
  double median = 0.0;
  double sigma = 0.0;
  double range = 0.0;
};

std::vector<ElementStats> element_stats(const Scan& scan, std::size_t per_view) {
  const std::size_t views = scan.geometry.n_views();
  std::vector<ElementStats> stats(per_view);
  util::parallel_for(per_view, [&](std::size_t begin, std::size_t end) {
    std::vector<double> r;
    for (std::size_t e = begin; e < end; ++e) {
      r.clear();
      for (std::size_t v = 0; v < views; ++v) {
        const float x = scan.measurement.data[v * per_view + e];
        if (std::isfinite(x)) r.push_back(x);
      }
      ElementStats& s = stats[e];
      s.finite = r.size();
      if (r.empty()) continue;
      std::sort(r.begin(), r.end());
      auto q = [&](double f) { return r[static_cast<std::size_t>(f * (r.size() - 1))]; };
      s.min = r.front();
      s.median = q(0.5);
      s.sigma = (q(0.75) - q(0.25)) / kIqrPerSigma;
      s.range = r.back() - r.front();
    }
  });
  return stats;
}

// Chessboard distance (in voxels) of every voxel to the nearest one with inside != 0, capped.
std::vector<std::uint16_t> distance_to_inside(const std::vector<std::uint8_t>& inside,
                                              const std::vector<std::size_t>& shape) {
  const std::size_t rank = shape.size();
  const long nx = static_cast<long>(shape[rank - 1]);
  const long ny = static_cast<long>(shape[rank - 2]);
  const long nz = rank == 3 ? static_cast<long>(shape[0]) : 1;
  std::vector<std::uint16_t> d(inside.size());
  for (std::size_t i = 0; i < inside.size(); ++i) d[i] = inside[i] ? 0 : kFar;
  // Two chamfer passes over all 3^rank - 1 neighbours: first those before each voxel in memory
  // order, then those after.
  for (int pass = 0; pass < 2; ++pass) {
    const long step = pass == 0 ? 1 : -1;
    const long z0 = pass == 0 ? 0 : nz - 1, y0 = pass == 0 ? 0 : ny - 1,
               x0 = pass == 0 ? 0 : nx - 1;
    for (long z = z0; z >= 0 && z < nz; z += step) {
      for (long y = y0; y >= 0 && y < ny; y += step) {
        for (long x = x0; x >= 0 && x < nx; x += step) {
          const std::size_t i = static_cast<std::size_t>((z * ny + y) * nx + x);
          std::uint32_t best = d[i];
          for (long dz = (rank == 3 ? -1 : 0); dz <= (rank == 3 ? 1 : 0); ++dz) {
            for (long dy = -1; dy <= 1; ++dy) {
              for (long dx = -1; dx <= 1; ++dx) {
                const long offset = (dz * ny + dy) * nx + dx;
                if (offset * step >= 0) continue;  // not yet visited in this pass
                const long zz = z + dz, yy = y + dy, xx = x + dx;
                if (zz < 0 || zz >= nz || yy < 0 || yy >= ny || xx < 0 || xx >= nx) continue;
                const std::size_t j = static_cast<std::size_t>((zz * ny + yy) * nx + xx);
                if (d[j] != kFar) best = std::min<std::uint32_t>(best, d[j] + 1u);
              }
            }
          }
          d[i] = static_cast<std::uint16_t>(std::min<std::uint32_t>(best, kFar));
        }
      }
    }
  }
  return d;
}

}  // namespace

namespace {

// The offsets an element reading only air may have: the air elements' spread, widened for the
// elements they miss.
struct AirBand {
  double lo = 0.0;
  double hi = 0.0;
};

// The elements reading air in every view (steady, near 0): the scan's noise and their offset
// band into `o`. Nullopt with o.note set when the scan shows too little air to trust.
std::optional<AirBand> air_band(const std::vector<ElementStats>& stats, std::size_t views,
                                std::size_t per_view, const OccupancySettings& settings,
                                Occupancy& o) {
  std::vector<double> spreads;
  for (const ElementStats& s : stats) {
    if (s.finite == views) spreads.push_back(s.sigma);
  }
  if (spreads.empty()) {
    o.note = "no detector element has a finite reading in every view";
    return std::nullopt;
  }
  std::sort(spreads.begin(), spreads.end());
  const double quiet = std::max(spreads[spreads.size() / 10], kNoiseFloor);
  std::vector<double> air_sigmas;
  std::vector<double> air_offsets;
  AirBand band{std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (const ElementStats& s : stats) {
    if (s.finite != views || s.sigma > kAirSpreadFactor * quiet ||
        s.range > kAirRangeSigmas * std::max(s.sigma, kNoiseFloor) ||
        std::fabs(s.median) > kMaxAirOffset)
      continue;
    air_sigmas.push_back(s.sigma);
    air_offsets.push_back(s.median);
    band.lo = std::min(band.lo, s.median);
    band.hi = std::max(band.hi, s.median);
  }
  o.air_elements = air_sigmas.size();
  if (air_sigmas.size() < std::max(kMinAirElements, per_view / 100)) {
    o.note = "too few detector elements read air in every view (" +
             std::to_string(air_sigmas.size()) + ")";
    return std::nullopt;
  }
  std::nth_element(air_offsets.begin(), air_offsets.begin() + air_offsets.size() / 2,
                   air_offsets.end());
  o.air_offset_median = air_offsets[air_offsets.size() / 2];
  if (std::fabs(o.air_offset_median) > kMaxAirLevel) {
    o.note = "the steadiest readings average " + std::to_string(o.air_offset_median) +
             ", not the 0 of air in a flat-field-normalised scan";
    return std::nullopt;
  }
  std::nth_element(air_sigmas.begin(), air_sigmas.begin() + air_sigmas.size() / 2,
                   air_sigmas.end());
  o.noise = std::max(air_sigmas[air_sigmas.size() / 2], kNoiseFloor);
  const double widen = 0.25 * (band.hi - band.lo) + settings.noise_sigmas * o.noise;
  band.lo -= widen;
  band.hi += widen;
  return band;
}

// certified[v * per_view + e]: this reading says the ray crossed only air (within
// `tolerance` of its element's offset, an offset inside the air band).
std::vector<std::uint8_t> certify_readings(const Scan& scan, const std::vector<ElementStats>& stats,
                                           std::size_t per_view, const AirBand& band, double noise,
                                           double tolerance) {
  const std::size_t views = scan.geometry.n_views();
  std::vector<std::uint8_t> certified(views * per_view, 0);
  for (std::size_t e = 0; e < per_view; ++e) {
    const ElementStats& s = stats[e];
    if (s.finite == 0) continue;
    const double offset = s.min + noise;
    if (offset < band.lo || offset > band.hi) continue;
    for (std::size_t v = 0; v < views; ++v) {
      const float x = scan.measurement.data[v * per_view + e];
      certified[v * per_view + e] = std::isfinite(x) && x - offset < tolerance;
    }
  }
  return certified;
}

// Whether view v certifies every element of the shadow of a voxel centred at p (a sphere
// circumscribing the voxel); false when the shadow leaves the detector.
bool shadow_certified(const Geometry& g, std::size_t v, const ViewRotation& rotation, const Vec3& p,
                      double radius, std::size_t rows, const std::vector<std::uint8_t>& certified) {
  const DetectorPoint d = project_to_detector(g, rotation, p);
  const double hu = radius * d.magnification / g.pitch_u;
  const double u0 = std::floor(d.u - hu), u1 = std::ceil(d.u + hu);
  if (!(u0 >= 0.0 && u1 <= static_cast<double>(g.n_u) - 1.0)) return false;
  double r0 = 0.0, r1 = 0.0;
  if (g.is_3d()) {
    const double hv = radius * d.magnification / g.pitch_v;
    r0 = std::floor(d.v - hv);
    r1 = std::ceil(d.v + hv);
    if (!(r0 >= 0.0 && r1 <= static_cast<double>(rows) - 1.0)) return false;
  }
  for (auto r = static_cast<std::size_t>(r0); r <= static_cast<std::size_t>(r1); ++r) {
    const std::uint8_t* line = certified.data() + (v * rows + r) * g.n_u;
    for (auto u = static_cast<std::size_t>(u0); u <= static_cast<std::size_t>(u1); ++u) {
      if (line[u] == 0) return false;
    }
  }
  return true;
}

// 0 for the voxels some view certifies as air, 1 elsewhere.
std::vector<std::uint8_t> carve(const Geometry& g, std::size_t rows,
                                const std::vector<std::uint8_t>& certified) {
  const std::size_t voxels = shape_size(g.volume_shape);
  const std::size_t rank = g.volume_shape.size();
  const std::size_t nx = g.volume_shape[rank - 1];
  const std::size_t ny = g.volume_shape[rank - 2];
  const double radius = 0.5 * g.voxel_mm * std::sqrt(static_cast<double>(rank));
  std::vector<std::uint8_t> inside(voxels, 1);
  std::vector<ViewRotation> rotations;
  for (std::size_t v = 0; v < g.n_views(); ++v) rotations.push_back(ViewRotation::of(g, v));
  util::parallel_for(voxels, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Vec3 p =
          voxel_centre(g, static_cast<double>(i % nx), static_cast<double>((i / nx) % ny),
                       static_cast<double>(i / (nx * ny)));
      for (std::size_t v = 0; v < g.n_views(); ++v) {
        if (shadow_certified(g, v, rotations[v], p, radius, rows, certified)) {
          inside[i] = 0;
          break;
        }
      }
    }
  });
  return inside;
}

}  // namespace

Occupancy carve_occupancy(const Scan& scan, const OccupancySettings& settings) {
  const Geometry& g = scan.geometry;
  const std::size_t rows = g.is_3d() ? g.n_v : 1;
  const std::size_t per_view = rows * g.n_u;
  const std::size_t voxels = shape_size(g.volume_shape);
  Occupancy o;
  o.inside.assign(voxels, 1);
  const std::vector<ElementStats> stats = element_stats(scan, per_view);
  const std::optional<AirBand> band = air_band(stats, g.n_views(), per_view, settings, o);
  if (!band) return o;
  const std::vector<std::uint8_t> certified =
      certify_readings(scan, stats, per_view, *band, o.noise, settings.noise_sigmas * o.noise);
  const std::vector<std::uint16_t> distance =
      distance_to_inside(carve(g, rows, certified), g.volume_shape);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < voxels; ++i) {
    o.inside[i] = distance[i] <= static_cast<std::uint16_t>(std::max(0, settings.margin_px));
    kept += o.inside[i];
  }
  o.carved = true;
  o.inside_fraction = static_cast<double>(kept) / static_cast<double>(voxels);
  return o;
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
  const std::vector<std::uint16_t> depth = distance_to_inside(outside, shape);
  const double ramp = 1.0 / (taper_px + 1.0);
  for (std::size_t i = 0; i < image.size(); ++i) {
    if (depth[i] <= taper_px) image[i] = static_cast<float>(image[i] * depth[i] * ramp);
  }
}

double clip_segments(std::vector<RaySegment>& segments, const Geometry& g,
                     const Occupancy& occupancy, double spacing_voxels) {
  double samples = 0.0;
  if (!occupancy.carved) {
    for (const RaySegment& s : segments) samples += s.count;
    return samples;
  }
  const std::vector<std::uint16_t> distance = distance_to_inside(occupancy.inside, g.volume_shape);
  const std::size_t rank = g.volume_shape.size();
  const long nx = static_cast<long>(g.volume_shape[rank - 1]);
  const long ny = static_cast<long>(g.volume_shape[rank - 2]);
  const long nz = rank == 3 ? static_cast<long>(g.volume_shape[0]) : 1;
  const double extent = sampling_domain(g).extent_mm;
  const double per_voxel = extent / g.voxel_mm;
  // Chessboard distance of sample k's voxel to the region (0: inside).
  auto distance_at = [&](const RaySegment& s, std::uint32_t k) {
    float pos[3];
    sample_position(s, k, 0.5f, pos);
    const double x = (pos[0] - 0.5) * per_voxel, y = (pos[1] - 0.5) * per_voxel,
                 z = (pos[2] - 0.5) * per_voxel;
    const long column = std::clamp(std::lround(x + 0.5 * (nx - 1)), 0L, nx - 1);
    const long row = std::clamp(std::lround(0.5 * (ny - 1) - y), 0L, ny - 1);
    const long slice = rank == 3 ? std::clamp(std::lround(z + 0.5 * (nz - 1)), 0L, nz - 1) : 0L;
    return static_cast<double>(
        distance[static_cast<std::size_t>((slice * ny + row) * nx + column)]);
  };
  // Samples that can be stepped over from one at distance d: every voxel closer than d is
  // outside, and m samples move at most floor(m spacing) + 1 voxels.
  auto skip = [&](double d) {
    return std::max<std::int64_t>(
        1, static_cast<std::int64_t>(std::ceil((d - 1.0) / spacing_voxels)) - 1);
  };
  const std::vector<double> kept =
      util::parallel_map_chunks(segments.size(), [&](std::size_t begin, std::size_t end) {
        double sum = 0.0;
        for (std::size_t r = begin; r < end; ++r) {
          RaySegment& s = segments[r];
          if (s.count == 0) continue;
          std::int64_t first = 0;
          while (first < s.count) {
            const double d = distance_at(s, static_cast<std::uint32_t>(first));
            if (d == 0.0) break;
            first += skip(d);
          }
          if (first >= s.count) {
            s.count = 0;
            continue;
          }
          std::int64_t last = s.count - 1;
          while (last > first) {
            const double d = distance_at(s, static_cast<std::uint32_t>(last));
            if (d == 0.0) break;
            last -= skip(d);
          }
          last = std::max(last, first);
          for (int a = 0; a < 3; ++a) s.start[a] += static_cast<float>(first) * s.step[a];
          s.count = static_cast<std::uint32_t>(last - first + 1);
          sum += s.count;
        }
        return sum;
      });
  for (double k : kept) samples += k;
  return samples;
}

}  // namespace riner::model
