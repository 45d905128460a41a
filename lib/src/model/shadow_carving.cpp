#include "model/shadow_carving.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "riner/array.hpp"
#include "riner/rays.hpp"
#include "util/parallel.hpp"

namespace riner::model {

namespace {

double voxel_radius(const Geometry& g) {
  return 0.5 * g.voxel_mm * std::sqrt(static_cast<double>(g.volume_shape.size()));
}

// A voxel's shadow around its centre's projection d: half widths in elements along the row
// (widened) and in rows. block_verdict bounds these over a block: one formula for both.
struct ShadowHalfWidths {
  double u = 0.0, v = 0.0;
};

ShadowHalfWidths shadow_half_widths(const Geometry& g, const DetectorPoint& d, double radius,
                                    double widen) {
  return {radius * d.magnification / g.pitch_u + widen, radius * d.magnification / g.pitch_v};
}

// Whether view v certifies every element of the shadow of a voxel centred at p.
bool shadow_certified(const Geometry& g, std::size_t v, const ViewRotation& rotation, const Vec3& p,
                      double radius, double widen, std::size_t rows,
                      const std::vector<std::uint8_t>& certified) {
  const DetectorPoint d = project_to_detector(g, rotation, p);
  const ShadowHalfWidths h = shadow_half_widths(g, d, radius, widen);
  const double u0 = std::floor(d.u - h.u), u1 = std::ceil(d.u + h.u);
  if (!(u0 >= 0.0 && u1 <= static_cast<double>(g.n_u) - 1.0)) return false;
  double r0 = 0.0, r1 = 0.0;
  if (g.is_3d()) {
    r0 = std::floor(d.v - h.v);
    r1 = std::ceil(d.v + h.v);
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

std::vector<ViewRotation> rotations_of(const Geometry& g) {
  std::vector<ViewRotation> rotations;
  for (std::size_t v = 0; v < g.n_views(); ++v) rotations.push_back(ViewRotation::of(g, v));
  return rotations;
}

// The grid as blocks of `side` voxels a side (the last ones cut by the grid's end).
struct Blocks {
  std::size_t side = 1;
  std::array<std::size_t, 3> count{1, 1, 1};  // x, y, z
  std::array<std::size_t, 3> size{1, 1, 1};   // the grid's voxels, x, y, z

  Blocks(const Geometry& g, std::size_t side_) : side(side_) {
    const std::size_t rank = g.volume_shape.size();
    size = {g.volume_shape[rank - 1], g.volume_shape[rank - 2], rank == 3 ? g.volume_shape[0] : 1};
    for (int a = 0; a < 3; ++a) count[a] = (size[a] + side - 1) / side;
  }
  std::size_t total() const { return count[0] * count[1] * count[2]; }
  // Block b's first voxel and one past its last, per axis.
  std::array<std::size_t, 3> first(std::size_t b) const {
    return {(b % count[0]) * side, (b / count[0] % count[1]) * side,
            (b / (count[0] * count[1])) * side};
  }
  std::array<std::size_t, 3> end(std::size_t b) const {
    const auto f = first(b);
    return {std::min(f[0] + side, size[0]), std::min(f[1] + side, size[1]),
            std::min(f[2] + side, size[2])};
  }
};

// A view's verdict on a whole block.
enum : std::uint8_t { kCertifiesNone = 0, kCertifiesAll = 1, kCertifiesSome = 2 };

// Per view, the certified readings summed over every rectangle of its elements.
class CertifiedSums {
 public:
  CertifiedSums(std::size_t rows, std::size_t n_u)
      : rows_(rows), n_u_(n_u), sums_((rows + 1) * (n_u + 1), 0) {}
  void load(const std::uint8_t* view) {
    for (std::size_t r = 0; r < rows_; ++r) {
      std::uint32_t along = 0;
      for (std::size_t u = 0; u < n_u_; ++u) {
        along += view[r * n_u_ + u];
        at(r + 1, u + 1) = at(r, u + 1) + along;
      }
    }
  }
  // Certified readings in rows [r0, r1] and elements [u0, u1].
  std::uint32_t in(std::size_t r0, std::size_t r1, std::size_t u0, std::size_t u1) const {
    return at(r1 + 1, u1 + 1) - at(r0, u1 + 1) - at(r1 + 1, u0) + at(r0, u0);
  }

 private:
  std::uint32_t& at(std::size_t r, std::size_t u) { return sums_[r * (n_u_ + 1) + u]; }
  std::uint32_t at(std::size_t r, std::size_t u) const { return sums_[r * (n_u_ + 1) + u]; }
  std::size_t rows_, n_u_;
  std::vector<std::uint32_t> sums_;
};

// What view v says of every voxel of a block whose voxel centres span the box between `low`
// and `high`. A voxel's shadow bounds (centre -+ radius x magnification, in elements) are
// ratios of affine functions of its centre with a positive denominator (the distance from the
// source), so over the box they are extreme at its corners: the corners' bounds hold every
// voxel's shadow (a hair wider for the rounding).
std::uint8_t block_verdict(const Geometry& g, const ViewRotation& rotation, const Vec3& low,
                           const Vec3& high, double radius, double widen, std::size_t rows,
                           const CertifiedSums& sums) {
  double lo_u = INFINITY, hi_u = -INFINITY, lo_v = INFINITY, hi_v = -INFINITY;
  const int corners = g.is_3d() ? 8 : 4;
  for (int c = 0; c < corners; ++c) {
    const Vec3 p{(c & 1) ? high.x : low.x, (c & 2) ? high.y : low.y, (c & 4) ? high.z : low.z};
    const DetectorPoint d = project_to_detector(g, rotation, p);
    const ShadowHalfWidths h = shadow_half_widths(g, d, radius, widen);
    lo_u = std::min(lo_u, d.u - h.u);
    hi_u = std::max(hi_u, d.u + h.u);
    if (g.is_3d()) {
      lo_v = std::min(lo_v, d.v - h.v);
      hi_v = std::max(hi_v, d.v + h.v);
    }
  }
  auto floor_of = [](double x) { return std::floor(x - 1e-9 * (1.0 + std::abs(x))); };
  auto ceil_of = [](double x) { return std::ceil(x + 1e-9 * (1.0 + std::abs(x))); };
  const double u0 = floor_of(lo_u), u1 = ceil_of(hi_u);
  const double r0 = g.is_3d() ? floor_of(lo_v) : 0.0, r1 = g.is_3d() ? ceil_of(hi_v) : 0.0;
  const double last_u = static_cast<double>(g.n_u) - 1.0;
  const double last_r = static_cast<double>(rows) - 1.0;
  // The part of the block's shadow on the detector.
  const double cu0 = std::max(u0, 0.0), cu1 = std::min(u1, last_u);
  const double cr0 = std::max(r0, 0.0), cr1 = std::min(r1, last_r);
  if (cu0 > cu1 || cr0 > cr1) return kCertifiesNone;  // every voxel's shadow leaves it
  const std::uint32_t count = sums.in(static_cast<std::size_t>(cr0), static_cast<std::size_t>(cr1),
                                      static_cast<std::size_t>(cu0), static_cast<std::size_t>(cu1));
  if (count == 0) return kCertifiesNone;
  const bool on_detector = u0 >= 0.0 && u1 <= last_u && r0 >= 0.0 && r1 <= last_r;
  const double area = (cu1 - cu0 + 1.0) * (cr1 - cr0 + 1.0);
  return on_detector && static_cast<double>(count) == area ? kCertifiesAll : kCertifiesSome;
}

}  // namespace

std::vector<std::uint8_t> carve_each_voxel(const Geometry& g, std::size_t rows,
                                           const std::vector<std::uint8_t>& certified,
                                           int min_views, double widen) {
  const Blocks grid(g, 1);
  const double radius = voxel_radius(g);
  const std::vector<ViewRotation> rotations = rotations_of(g);
  std::vector<std::uint8_t> inside(grid.total(), 1);
  util::parallel_for(inside.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const auto at = grid.first(i);
      const Vec3 p = voxel_centre(g, static_cast<double>(at[0]), static_cast<double>(at[1]),
                                  static_cast<double>(at[2]));
      int views = 0;
      for (std::size_t v = 0; v < g.n_views() && views < min_views; ++v) {
        views += shadow_certified(g, v, rotations[v], p, radius, widen, rows, certified);
      }
      inside[i] = views < min_views;
    }
  });
  return inside;
}

std::vector<std::uint8_t> carve_by_shadows(const Geometry& g, std::size_t rows,
                                           const std::vector<std::uint8_t>& certified,
                                           int min_views, double widen) {
  // 8^3 and 16^2 voxels: a few hundred voxels a block, few blocks against a grid (not tuned).
  const Blocks blocks(g, g.is_3d() ? 8 : 16);
  const std::size_t views = g.n_views();
  const double radius = voxel_radius(g);
  const std::vector<ViewRotation> rotations = rotations_of(g);
  // Each block's box of voxel centres.
  std::vector<std::pair<Vec3, Vec3>> boxes(blocks.total());
  for (std::size_t b = 0; b < boxes.size(); ++b) {
    const auto f = blocks.first(b), e = blocks.end(b);
    boxes[b] = {voxel_centre(g, static_cast<double>(f[0]), static_cast<double>(f[1]),
                             static_cast<double>(f[2])),
                voxel_centre(g, static_cast<double>(e[0] - 1), static_cast<double>(e[1] - 1),
                             static_cast<double>(e[2] - 1))};
  }
  std::vector<std::uint8_t> verdicts(blocks.total() * views);
  util::parallel_for(views, [&](std::size_t begin, std::size_t end) {
    CertifiedSums sums(rows, g.n_u);
    for (std::size_t v = begin; v < end; ++v) {
      sums.load(certified.data() + v * rows * g.n_u);
      for (std::size_t b = 0; b < boxes.size(); ++b) {
        // voxel_centre's y and x run against the indices: the box's corners in any order.
        verdicts[b * views + v] = block_verdict(g, rotations[v], boxes[b].first, boxes[b].second,
                                                radius, widen, rows, sums);
      }
    }
  });
  std::vector<std::uint8_t> inside(shape_size(g.volume_shape), 1);
  util::parallel_for(blocks.total(), [&](std::size_t begin, std::size_t end) {
    std::vector<std::size_t> some;
    for (std::size_t b = begin; b < end; ++b) {
      const std::uint8_t* verdict = verdicts.data() + b * views;
      int all = 0;
      some.clear();
      for (std::size_t v = 0; v < views; ++v) {
        all += verdict[v] == kCertifiesAll;
        if (verdict[v] == kCertifiesSome) some.push_back(v);
      }
      const auto f = blocks.first(b), e = blocks.end(b);
      for (std::size_t z = f[2]; z < e[2]; ++z) {
        for (std::size_t y = f[1]; y < e[1]; ++y) {
          for (std::size_t x = f[0]; x < e[0]; ++x) {
            int certifying = all;
            if (certifying < min_views && !some.empty()) {
              const Vec3 p = voxel_centre(g, static_cast<double>(x), static_cast<double>(y),
                                          static_cast<double>(z));
              for (std::size_t i = 0; i < some.size() && certifying < min_views; ++i) {
                certifying += shadow_certified(g, some[i], rotations[some[i]], p, radius, widen,
                                               rows, certified);
              }
            }
            inside[(z * blocks.size[1] + y) * blocks.size[0] + x] = certifying < min_views;
          }
        }
      }
    }
  });
  return inside;
}

}  // namespace riner::model
