// Where each detector ray crosses the reconstruction region, and how it is sampled there
// (METHOD.md §2: points at a fixed interval, only inside the region). Computed once per scan on
// the host in double and stored in float, so both engines sample exactly the same points.
//
// Coordinates are normalised to the encoding's domain: the cube (square in 2D) of side
// `extent` = the grid's largest side, centred on the origin, mapped to [0, 1]^d.
#pragma once

#include <cstdint>
#include <vector>

#include "riner/geometry.hpp"
#include "riner/rays.hpp"

namespace riner::model {

// Host mirror of the float8 a kernel reads per ray.
struct RaySegment {
  float start[3];       // normalised position where the sampled part begins
  float step[3];        // normalised advance per sample
  float dx;             // mm per sample: the ray sum is sum(mu) * dx
  std::uint32_t count;  // samples (0: the ray misses the region)
};
static_assert(sizeof(RaySegment) == 32);

struct SamplingDomain {
  double extent_mm = 1.0;  // side of the normalised cube
  int dims = 2;
};

SamplingDomain sampling_domain(const Geometry& g);

// spacing_mm: the nominal interval; each ray's own interval is its length / ceil(length /
// spacing) so the samples tile it exactly. circle: clip to the inscribed circle/cylinder
// instead of the box.
std::vector<RaySegment> ray_segments(const Geometry& g, double spacing_mm, bool circle);

// The scan's rays as training samples them: ray_segments, each clipped to the samples it keeps.
// A table of 32 bytes per reading is most of a volume's memory (the chest CT's 21.6 million
// readings: 691 MB of about 1.6 GB), so past `table_bytes` only each ray's clip is held (8 bytes)
// and its segment is computed again from the geometry when it is drawn: the same floats.
class RaySegments {
 public:
  static constexpr std::size_t kTableBytes = std::size_t{256} << 20;

  // Whether `rays` rays are held as a table (else as their clips), and the bytes they take.
  static bool tabled_for(std::size_t rays, std::size_t table_bytes = kTableBytes) {
    return rays * sizeof(RaySegment) <= table_bytes;
  }
  static std::size_t held_bytes(std::size_t rays) {
    return rays * (tabled_for(rays) ? sizeof(RaySegment) : 2 * sizeof(std::uint32_t));
  }

  RaySegments() = default;
  RaySegments(const Geometry& g, double spacing_mm, bool circle,
              std::size_t table_bytes = kTableBytes);
  // Segments given as they are (a warm start's fit to pixels, tests).
  explicit RaySegments(std::vector<RaySegment> table);

  std::size_t size() const { return tabled() ? table_.size() : counts_.size(); }
  bool tabled() const { return !table_.empty() || counts_.empty(); }
  RaySegment operator[](std::size_t ray) const;
  std::uint32_t count(std::size_t ray) const { return tabled() ? table_[ray].count : counts_[ray]; }
  // Keeps samples [first, first + count) of the ray's segment as it is now (count 0: none).
  void clip(std::size_t ray, std::uint32_t first, std::uint32_t count);

 private:
  Geometry geometry_;
  SamplingDomain domain_;
  std::vector<ViewRotation> rotations_;
  double spacing_mm_ = 1.0;
  bool circle_ = false;
  std::vector<RaySegment> table_;
  std::vector<std::uint32_t> firsts_, counts_;  // when not tabled
};

// Sample k of a segment at fractional offset u in [0, 1) within its interval (0.5: midpoint).
inline void sample_position(const RaySegment& s, std::uint32_t k, float u, float out[3]) {
  const float t = static_cast<float>(k) + u;
  for (int d = 0; d < 3; ++d) out[d] = s.start[d] + t * s.step[d];
}

// Normalised coordinates of voxel centres, [n][dims], in the grid's C order.
std::vector<float> voxel_positions(const Geometry& g);

}  // namespace riner::model
