#include "model/object_seen_by_fbp.hpp"

#include <algorithm>
#include <cmath>

#include "model/chessboard_distance.hpp"
#include "preprocessing/stripes.hpp"
#include "riner/array.hpp"
#include "riner/fbp.hpp"
#include "riner/geometry.hpp"
#include "riner/rays.hpp"
#include "rings/radial.hpp"
#include "util/along_each_axis.hpp"
#include "util/gaussian_blur.hpp"
#include "util/parallel.hpp"
#include "util/robust_statistics.hpp"

namespace riner::model {

namespace {

constexpr std::size_t kLargestSide2d = 512;
constexpr std::size_t kLargestSide3d = 128;
// Binned elements a detector row keeps at least (and rows in 3D).
constexpr std::size_t kFewestColumns = 32;
constexpr std::size_t kFewestRows = 8;
constexpr std::size_t kStripeReach = 25;
constexpr double kBlurVoxels = 1.0;
constexpr std::uint16_t kAirDistance = 3;
constexpr std::size_t kMinAirVoxels = 64;
// Artifacts (a bright edge's ringing, the rings left, streaks) swing both ways, an object only
// up: a voxel is object only above this many times the deepest dip within kDipReach binned
// voxels (the paper's Shepp-Logan skull rings into 16% of the grid's air without it).
constexpr double kDipRatio = 1.5;
constexpr long kDipReach = 12;
constexpr std::size_t kMinRingAir = 8;
// Beside a bright edge its blur spills over into the air: a voxel is object only above this share
// of the brightest within kSpillReach binned voxels (without it the skull of the demo's
// Shepp-Logan spilled a 10-pixel band around the head into the region). A faint object keeps
// its level near its own edge (the square's corners: about all of it).
constexpr double kSpillShare = 0.3;
constexpr long kSpillReach = 3;
// Voxels of the scan's grid the carved object the FBP sees grows by.
constexpr int kObjectGrowthVoxels = 4;
// The noise never reads below this share of the blurred image's 99th percentile (noise-free
// simulations).
constexpr double kNoiseFloorShare = 1e-3;

std::size_t bin_factor(const Geometry& g) {
  const std::size_t largest = *std::max_element(g.volume_shape.begin(), g.volume_shape.end());
  std::size_t f = std::max<std::size_t>(1, largest / (g.is_3d() ? kLargestSide3d : kLargestSide2d));
  f = std::min(f, std::max<std::size_t>(1, g.n_u / kFewestColumns));
  if (g.is_3d()) f = std::min(f, std::max<std::size_t>(1, g.n_v / kFewestRows));
  return f;
}

// Binned element j' covers elements f j' .. f j' + f - 1 of n; the offset that puts it there.
double binned_offset(double offset, std::size_t n, std::size_t f, std::size_t binned) {
  const double fd = static_cast<double>(f);
  return (0.5 * (fd - 1.0) - 0.5 * (static_cast<double>(n) - 1.0) + offset) / fd +
         0.5 * (static_cast<double>(binned) - 1.0);
}

// The binned voxel whose centre is nearest voxel k's on an axis of n (binned: nb).
std::size_t binned_index(std::size_t k, std::size_t n, std::size_t f, std::size_t nb) {
  const double x =
      (static_cast<double>(k) - 0.5 * (static_cast<double>(n) - 1.0)) / static_cast<double>(f) +
      0.5 * (static_cast<double>(nb) - 1.0);
  return static_cast<std::size_t>(std::clamp(std::lround(x), 0L, static_cast<long>(nb) - 1));
}

Geometry binned_geometry(const Geometry& g, std::size_t f) {
  Geometry b = g;
  b.n_u = g.n_u / f;
  b.pitch_u = g.pitch_u * static_cast<double>(f);
  b.offset_u = binned_offset(g.offset_u, g.n_u, f, b.n_u);
  if (g.is_3d()) {
    b.n_v = g.n_v / f;
    b.pitch_v = g.pitch_v * static_cast<double>(f);
    b.offset_v = binned_offset(g.offset_v, g.n_v, f, b.n_v);
  }
  for (std::size_t& n : b.volume_shape) n = (n + f - 1) / f;
  b.voxel_mm = g.voxel_mm * static_cast<double>(f);
  return b;
}

Scan binned_scan(const Scan& scan, std::size_t f) {
  const Geometry& g = scan.geometry;
  const Geometry b = binned_geometry(g, f);
  const std::size_t rows = g.is_3d() ? g.n_v : 1, binned_rows = g.is_3d() ? b.n_v : 1;
  const std::size_t fv = g.is_3d() ? f : 1;
  Array m(b.measurement_shape());
  util::parallel_for(b.n_views() * binned_rows, [&](std::size_t begin, std::size_t end) {
    for (std::size_t line = begin; line < end; ++line) {
      const std::size_t view = line / binned_rows, row = line % binned_rows;
      for (std::size_t j = 0; j < b.n_u; ++j) {
        double sum = 0.0;
        int n = 0;
        for (std::size_t r = row * fv; r < (row + 1) * fv; ++r) {
          const float* in = scan.measurement.ptr() + (view * rows + r) * g.n_u;
          for (std::size_t u = j * f; u < (j + 1) * f; ++u) {
            if (!std::isfinite(in[u])) continue;
            sum += in[u];
            ++n;
          }
        }
        m.data[line * b.n_u + j] = n > 0 ? static_cast<float>(sum / n) : NAN;
      }
    }
  });
  preprocessing::remove_stripes(m, b, kStripeReach);
  return Scan{std::move(m), b, 0};
}

// Whether a point is inside the field every view sees whole, `margin` inside its edge.
bool in_field(const Vec3& p, const FieldOfView& field, const Geometry& g, double margin) {
  if (std::hypot(p.x, p.y) > field.radius_mm - margin) return false;
  return !g.is_3d() || std::fabs(p.z - field.centre_z_mm) <= field.half_height_mm - margin;
}

// The rings the stripes left (the running median's own error makes broad ones): per axial slice,
// the median of the air at each radius from the axis (in voxels, rounded), taken off every
// voxel at that radius; radii with fewer than kMinRingAir air voxels keep theirs.
void remove_air_rings(std::vector<float>& image, const std::vector<std::size_t>& shape,
                      const std::vector<std::uint8_t>& is_air) {
  const std::size_t rank = shape.size();
  const std::size_t nx = shape[rank - 1], ny = shape[rank - 2];
  const std::size_t slices = image.size() / (nx * ny);
  const rings::PixelRadii radii(ny, nx, 1.0);
  const std::size_t bins = radii.nearest_nodes();
  util::parallel_for(slices, [&](std::size_t begin, std::size_t end) {
    std::vector<std::vector<double>> air(bins);
    std::vector<double> ring(bins);
    for (std::size_t z = begin; z < end; ++z) {
      for (auto& a : air) a.clear();
      const std::size_t first = z * nx * ny, last = first + nx * ny;
      for (std::size_t i = first; i < last; ++i) {
        if (is_air[i]) air[radii.nearest(i - first)].push_back(image[i]);
      }
      for (std::size_t r = 0; r < bins; ++r) {
        ring[r] = air[r].size() >= kMinRingAir ? util::quantile(air[r], 0.5) : 0.0;
      }
      for (std::size_t i = first; i < last; ++i) {
        image[i] -= static_cast<float>(ring[radii.nearest(i - first)]);
      }
    }
  });
}

// The voxels of `object` joined to a `kept` one through object voxels (3^d - 1 neighbours): an
// island of object out in the carved air is a streak's or a ring's bright spot far more often
// than a separate faint object, and training it leaves specks at its outline (the wood's air:
// specks 2.4 -> 4.5 per 10^4 with islands).
std::vector<std::uint8_t> touching(const std::vector<std::uint8_t>& object,
                                   const std::vector<std::uint8_t>& kept,
                                   const std::vector<std::size_t>& shape) {
  const std::size_t rank = shape.size();
  const long nx = static_cast<long>(shape[rank - 1]), ny = static_cast<long>(shape[rank - 2]);
  const long nz = rank == 3 ? static_cast<long>(shape[0]) : 1;
  std::vector<std::uint8_t> out(object.size(), 0);
  std::vector<std::size_t> stack;
  for (std::size_t i = 0; i < object.size(); ++i) {
    if (object[i] && kept[i]) {
      out[i] = 1;
      stack.push_back(i);
    }
  }
  while (!stack.empty()) {
    const std::size_t i = stack.back();
    stack.pop_back();
    const long x = static_cast<long>(i) % nx, y = (static_cast<long>(i) / nx) % ny,
               z = static_cast<long>(i) / (nx * ny);
    for (long dz = nz > 1 ? -1 : 0; dz <= (nz > 1 ? 1 : 0); ++dz) {
      for (long dy = -1; dy <= 1; ++dy) {
        for (long dx = -1; dx <= 1; ++dx) {
          const long xx = x + dx, yy = y + dy, zz = z + dz;
          if (xx < 0 || xx >= nx || yy < 0 || yy >= ny || zz < 0 || zz >= nz) continue;
          const auto j = static_cast<std::size_t>((zz * ny + yy) * nx + xx);
          if (!object[j] || out[j]) continue;
          out[j] = 1;
          stack.push_back(j);
        }
      }
    }
  }
  return out;
}

// The smallest (or with `largest`, the largest) value within `reach` voxels (chessboard) of each
// voxel: over a box, one axis at a time.
std::vector<float> box_extreme(const std::vector<float>& data,
                               const std::vector<std::size_t>& shape, long reach, bool largest) {
  return util::along_each_axis(
      data, shape, [&](const float* in, float* out, std::size_t size, std::size_t stride) {
        const long n = static_cast<long>(size);
        for (long i = 0; i < n; ++i) {
          float m = in[static_cast<std::size_t>(i) * stride];
          for (long j = std::max(0L, i - reach); j <= std::min(n - 1, i + reach); ++j) {
            const float x = in[static_cast<std::size_t>(j) * stride];
            m = largest ? std::max(m, x) : std::min(m, x);
          }
          out[static_cast<std::size_t>(i) * stride] = m;
        }
      });
}

}  // namespace

ObjectSeenByFbp object_seen_by_fbp(const Scan& scan, const std::vector<std::uint8_t>& kept,
                                   const FbpCheckSettings& settings) {
  const Geometry& g = scan.geometry;
  ObjectSeenByFbp out;
  out.bin = bin_factor(g);
  const std::size_t f = out.bin;
  const Scan binned = binned_scan(scan, f);
  const Geometry& b = binned.geometry;
  FbpOptions options;
  options.stopped_beam_at_floor = false;  // no metal streaks in what training reads
  options.filter = FbpFilter::kHann;
  options.engine = settings.engine;
  options.device = settings.device;
  std::vector<float> image =
      util::gaussian_blur(fbp(binned, options).data, b.volume_shape, kBlurVoxels);

  const std::size_t rank = g.volume_shape.size();
  const std::size_t nx = g.volume_shape[rank - 1], ny = g.volume_shape[rank - 2];
  const std::size_t bx = b.volume_shape[rank - 1], by = b.volume_shape[rank - 2];
  const std::size_t nz = rank == 3 ? g.volume_shape[0] : 1, bz = rank == 3 ? b.volume_shape[0] : 1;
  auto binned_of = [&](std::size_t i) {
    const std::size_t x = binned_index(i % nx, nx, f, bx);
    const std::size_t y = binned_index((i / nx) % ny, ny, f, by);
    const std::size_t z = binned_index(i / (nx * ny), nz, f, bz);
    return (z * by + y) * bx + x;
  };
  std::vector<std::uint8_t> binned_kept(image.size(), 0);
  for (std::size_t i = 0; i < kept.size(); ++i) {
    if (kept[i]) binned_kept[binned_of(i)] = 1;
  }
  const std::vector<std::uint16_t> distance = chessboard_distance(binned_kept, b.volume_shape);
  const FieldOfView field = field_of_view(b);
  const double margin = b.voxel_mm * std::sqrt(static_cast<double>(rank));
  std::vector<std::uint8_t> in_view(image.size()), is_air(image.size());
  for (std::size_t i = 0; i < image.size(); ++i) {
    const Vec3 p = voxel_centre(b, static_cast<double>(i % bx), static_cast<double>((i / bx) % by),
                                static_cast<double>(i / (bx * by)));
    in_view[i] = in_field(p, field, b, margin);
    is_air[i] = in_view[i] && distance[i] >= kAirDistance;
  }
  remove_air_rings(image, b.volume_shape, is_air);
  std::vector<double> air;
  for (std::size_t i = 0; i < image.size(); ++i) {
    if (is_air[i]) air.push_back(image[i]);
  }
  out.air_voxels = air.size();
  if (air.size() < kMinAirVoxels) return out;
  out.level = util::quantile(air, 0.5);
  for (double& a : air) a = std::fabs(a - out.level);
  std::vector<double> magnitudes(image.begin(), image.end());
  for (double& m : magnitudes) m = std::fabs(m);
  out.noise = std::max(util::kMadToSigma * util::quantile(air, 0.5),
                       kNoiseFloorShare * util::quantile(magnitudes, 0.99));
  const std::vector<float> deepest = box_extreme(image, b.volume_shape, kDipReach, false);
  const std::vector<float> highest = box_extreme(image, b.volume_shape, kSpillReach, true);
  std::vector<std::uint8_t> object(image.size(), 0);
  for (std::size_t i = 0; i < image.size(); ++i) {
    const double dip = std::max(0.0, out.level - deepest[i]);
    const double spill = kSpillShare * std::max(0.0, highest[i] - out.level);
    const double threshold =
        out.level + std::max({settings.sigmas * out.noise, kDipRatio * dip, spill});
    object[i] = in_view[i] && image[i] > threshold;
  }
  object = touching(object, binned_kept, b.volume_shape);
  // What the rays carved and the FBP sees, grown on the scan's grid: around object the rays kept
  // their margin is enough, and growing there too kept a band of air around the wood where its
  // edge then trained into specks (4.5 per 10^4 against 2.4).
  std::vector<std::uint8_t> carved_object(kept.size(), 0);
  for (std::size_t i = 0; i < kept.size(); ++i) {
    carved_object[i] = !kept[i] && object[binned_of(i)];
  }
  out.object = dilated(carved_object, g.volume_shape, static_cast<int>(kObjectGrowthVoxels));
  out.usable = true;
  return out;
}

}  // namespace riner::model
