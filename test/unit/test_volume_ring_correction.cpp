// Ring corrections of a parallel-beam volume, slice by slice: a ring in one slice leaves that
// slice for its row of alpha and nothing else moves; slices between rows, cone beams and bad
// input are left alone or refused.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "riner/error.hpp"
#include "riner/rays.hpp"
#include "riner/ring_correction.hpp"
#include "riner/volume_ring_correction.hpp"
#include "support/geometries.hpp"

namespace {

constexpr std::size_t kSlices = 5;
constexpr std::size_t kSide = 128;
constexpr std::size_t kRingSlice = 2;

// 5 slices of 128 x 128 (1 mm), 181 columns and 5 rows of 1 mm: row r lies in slice r.
riner::Geometry volume_geometry(riner::GeometryType type = riner::GeometryType::kParallel3d) {
  return riner::test::make_geometry(type, 90, 181, kSlices, {kSlices, kSide, kSide}, 1.0, 1.0,
                                    M_PI);
}

// Every slice: the 2D tests' ellipse of soft tissue (40 x 22 mm) with a denser insert off the
// axis, in air (test_ring_correction.cpp). With `ring`, slice kRingSlice also carries their
// narrow ring inside the object (radius 8-10 mm, -0.0006/mm), as training leaves them.
riner::Array volume(const riner::Geometry& g, bool ring) {
  riner::Array out(g.volume_shape);
  for (std::size_t s = 0; s < kSlices; ++s) {
    for (std::size_t i = 0; i < kSide; ++i) {
      for (std::size_t k = 0; k < kSide; ++k) {
        const riner::Vec3 c = riner::voxel_centre(g, static_cast<double>(k), static_cast<double>(i),
                                                  static_cast<double>(s));
        float v = 0.0f;
        if ((c.x / 40) * (c.x / 40) + (c.y / 22) * (c.y / 22) <= 1.0) v = 0.02f;
        if (std::hypot(c.x - 15.0, c.y - 5.0) < 5.0) v = 0.03f;
        const long bin = std::lround(2.0 * std::hypot(c.x, c.y));
        if (ring && s == kRingSlice && bin >= 16 && bin <= 20) v -= 0.0006f;
        out.data[(s * kSide + i) * kSide + k] = v;
      }
    }
  }
  return out;
}

// Rms of a - b over slice s.
double slice_rms(const riner::Array& a, const riner::Array& b, std::size_t s) {
  double sum = 0.0;
  const std::size_t n = kSide * kSide;
  for (std::size_t p = s * n; p < (s + 1) * n; ++p) {
    const double d = static_cast<double>(a.data[p]) - b.data[p];
    sum += d * d;
  }
  return std::sqrt(sum / static_cast<double>(n));
}

// Largest |ln(alpha_new / alpha)| over row r.
double row_change(const riner::Array& after, const riner::Array& before, std::size_t n_u,
                  std::size_t r) {
  double largest = 0.0;
  for (std::size_t e = r * n_u; e < (r + 1) * n_u; ++e) {
    largest = std::max(largest, std::fabs(std::log(double(after.data[e]) / before.data[e])));
  }
  return largest;
}

}  // namespace

TEST_SUITE("volume_ring_correction") {
  TEST_CASE("a ring in one slice goes into that slice's row of alpha; the others stay") {
    const riner::Geometry g = volume_geometry();
    CHECK(riner::rows_of_slices(g) == std::vector<long>{0, 1, 2, 3, 4});
    const riner::Array truth = volume(g, false);
    const riner::Array trained = volume(g, true);
    riner::Array alpha({g.n_v, g.n_u});
    for (std::size_t e = 0; e < alpha.size(); ++e) alpha.data[e] = e % 2 ? 0.97f : 1.03f;

    // The radial-gradient correction alone, the one that sees a ring inside the object.
    riner::RingCorrectionConfig gradient;
    gradient.air_reference = false;
    gradient.response_reference = false;
    gradient.mirror_reference = false;
    const riner::VolumeRingCorrection c =
        riner::correct_rings_per_slice(trained, alpha, g, {}, gradient);
    CHECK(c.note.empty());
    CHECK(c.slices == kSlices);
    CHECK(c.gradient_applied >= 1);
    // The ring's slice is exactly the 2D correction of that slice with its row of alpha (on
    // this phantom the ring's rms falls from 5.6e-5 to 2.6e-5/mm: its broad part stays, by
    // the high-pass's design); its row takes the ring's projections.
    const double before = slice_rms(trained, truth, kRingSlice);
    const double after = slice_rms(c.image, truth, kRingSlice);
    MESSAGE("ring slice rms " << before << " -> " << after);
    CHECK(after < 0.5 * before);
    const std::size_t n = kSide * kSide;
    riner::Array slice({kSide, kSide});
    std::copy_n(trained.data.begin() + kRingSlice * n, n, slice.data.begin());
    riner::Array row({g.n_u});
    std::copy_n(alpha.data.begin() + kRingSlice * g.n_u, g.n_u, row.data.begin());
    const riner::Geometry flat = riner::test::make_geometry(riner::GeometryType::kParallel2d, 90,
                                                            181, 1, {kSide, kSide}, 1.0, 1.0, M_PI);
    const riner::RingCorrection twin = riner::correct_rings_from_gradient(slice, row, flat);
    CHECK(std::equal(twin.image.data.begin(), twin.image.data.end(),
                     c.image.data.begin() + kRingSlice * n));
    CHECK(std::equal(twin.alpha.data.begin(), twin.alpha.data.end(),
                     c.alpha.data.begin() + kRingSlice * g.n_u));
    const double ring_row = row_change(c.alpha, alpha, g.n_u, kRingSlice);
    CHECK(ring_row > 0.002);
    // Every other slice and row: changed by less than a tenth of the ring's.
    for (std::size_t s = 0; s < kSlices; ++s) {
      if (s == kRingSlice) continue;
      CAPTURE(s);
      CHECK(slice_rms(c.image, trained, s) < 0.1 * before);
      CHECK(row_change(c.alpha, alpha, g.n_u, s) < 0.1 * ring_row);
    }
    // All the corrections, as the Reconstructor runs them: every slice is a 2D scan.
    const riner::VolumeRingCorrection all =
        riner::correct_rings_per_slice(trained, alpha, g, {}, riner::RingCorrectionConfig{});
    CHECK(all.slices == kSlices);
    CHECK(slice_rms(all.image, truth, kRingSlice) < 0.5 * before);
  }

  TEST_CASE("slices between rows, and cone beams, are left as trained with a note") {
    riner::Geometry half = volume_geometry();
    half.offset_v = 0.5;  // every row half-way between two slices
    const riner::Array trained = volume(half, true);
    const riner::Array alpha({half.n_v, half.n_u}, 1.0f);
    CHECK(riner::rows_of_slices(half) == std::vector<long>(kSlices, -1));
    const riner::VolumeRingCorrection between =
        riner::correct_rings_per_slice(trained, alpha, half, {}, riner::RingCorrectionConfig{});
    CHECK(between.slices == 0);
    CHECK_FALSE(between.note.empty());
    CHECK(between.image.data == trained.data);
    CHECK(between.alpha.data == alpha.data);

    riner::Geometry fine = volume_geometry();
    fine.pitch_v = 2.0;  // rows 2 mm apart over 1 mm slices: slices 0, 2, 4 have a row
    CHECK(riner::rows_of_slices(fine) == std::vector<long>{1, -1, 2, -1, 3});

    const riner::Geometry cone = volume_geometry(riner::GeometryType::kCone3d);
    const riner::VolumeRingCorrection c =
        riner::correct_rings_per_slice(trained, alpha, cone, {}, riner::RingCorrectionConfig{});
    CHECK(c.slices == 0);
    CHECK(c.note.find("cone") != std::string::npos);
    CHECK(c.image.data == trained.data);
  }

  TEST_CASE(
      "bad input: a 2D geometry, a volume or alpha of the wrong shape, a dead pixel off "
      "the detector") {
    const riner::Geometry g = volume_geometry();
    const riner::Array trained = volume(g, false);
    const riner::Array alpha({g.n_v, g.n_u}, 1.0f);
    const riner::RingCorrectionConfig config;
    CHECK_THROWS_AS(
        riner::correct_rings_per_slice(trained, alpha, riner::test::small_parallel2d(), {}, config),
        riner::InputError);
    CHECK_THROWS_AS(riner::correct_rings_per_slice(riner::Array({kSlices, kSide, kSide + 1}), alpha,
                                                   g, {}, config),
                    riner::InputError);
    CHECK_THROWS_AS(
        riner::correct_rings_per_slice(trained, riner::Array({g.n_u}, 1.0f), g, {}, config),
        riner::InputError);
    CHECK_THROWS_AS(riner::correct_rings_per_slice(trained, alpha, g, {g.n_u * g.n_v}, config),
                    riner::InputError);
  }
}
