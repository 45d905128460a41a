// The air-referenced ring correction: rings whose circles cross air leave the image, go into
// alpha, and the data fit stays what it was; images without air, or with a uniform background,
// are left alone.
#include <doctest/doctest.h>

#include <cmath>

#include "reference/project_ref.hpp"
#include "riner/error.hpp"
#include "riner/rays.hpp"
#include "riner/ring_correction.hpp"
#include "support/geometries.hpp"

namespace {

// A 128 x 128 grid of 1 mm seen by a fan beam with margin.
riner::Geometry ring_geometry() {
  return riner::test::make_geometry(riner::GeometryType::kFan2d, 32, 181, 1, {128, 128}, 1.5, 1.0);
}

// Radius bins of the correction: half a pixel, centred on multiples of 0.5 mm here.
long radius_bin(const riner::Vec3& c) { return std::lround(2.0 * std::hypot(c.x, c.y)); }

// A smooth ring: +0.0004/mm at radius 29 mm falling to 0 at 25 and 33 mm (a raised cosine),
// faint (below the air threshold) as the rings training leaves are. Constant over each radius
// bin, so the correction can remove it exactly.
float outer_ring(long bin) {
  const double r = 0.5 * static_cast<double>(bin);
  return std::fabs(r - 29.0) < 4.0
             ? static_cast<float>(0.0002 * (1.0 + std::cos(M_PI * (r - 29.0) / 4.0)))
             : 0.0f;
}

// Ellipse of soft tissue (semi-axes 40 x 22 mm) with a denser insert off the axis; `rings` adds
// the outer ring, which crosses air, and one inside the object (8-10 mm, -0.0006/mm).
riner::Array phantom(const riner::Geometry& g, bool rings, float background = 0.0f) {
  riner::Array image(g.volume_shape, background);
  for (std::size_t i = 0; i < 128; ++i) {
    for (std::size_t k = 0; k < 128; ++k) {
      const riner::Vec3 c = riner::voxel_centre(g, static_cast<double>(k), static_cast<double>(i));
      float v = background;
      if ((c.x / 40) * (c.x / 40) + (c.y / 22) * (c.y / 22) <= 1.0) v = 0.02f;
      if (std::hypot(c.x - 15.0, c.y - 5.0) < 5.0) v = 0.03f;
      const long b = radius_bin(c);
      if (rings) v += outer_ring(b);
      if (rings && b >= 16 && b <= 20) v -= 0.0006f;
      image(i, k) = v;
    }
  }
  return image;
}

riner::Array ring_inside_only(const riner::Geometry& g) {
  riner::Array image(g.volume_shape);
  for (std::size_t i = 0; i < 128; ++i) {
    for (std::size_t k = 0; k < 128; ++k) {
      const riner::Vec3 c = riner::voxel_centre(g, static_cast<double>(k), static_cast<double>(i));
      const long b = radius_bin(c);
      image(i, k) = b >= 16 && b <= 20 ? -0.0006f : 0.0f;
    }
  }
  return image;
}

// -ln(alpha_e) + (P image)(view, e): what the model predicts for every reading.
std::vector<double> predicted(const riner::Geometry& g, const riner::Array& image,
                              const riner::Array& alpha) {
  std::vector<double> out =
      riner::ref::project(g, std::vector<double>(image.data.begin(), image.data.end()));
  for (std::size_t j = 0; j < out.size(); ++j) out[j] -= std::log(alpha.data[j % g.n_u]);
  return out;
}

}  // namespace

TEST_SUITE("ring_correction") {
  TEST_CASE("a ring crossing air leaves the image for alpha and the data fit is unchanged") {
    const riner::Geometry g = ring_geometry();
    const riner::Array truth = phantom(g, false);
    const riner::Array trained = phantom(g, true);
    riner::Array alpha({g.n_u});
    for (std::size_t e = 0; e < g.n_u; ++e)
      alpha.data[e] = 0.8f + 0.003f * static_cast<float>(e % 50);

    // Without the profile smoothing (which damps a ring this narrow by ~25% at its peak), the
    // removal is exact.
    riner::AirRingSettings exact;
    exact.smoothing_bins = 0.0;
    const riner::AirRingCorrection c = riner::correct_rings_from_air(trained, alpha, g, exact);
    CHECK(c.applied);
    CHECK(c.measured_radii > 20);
    CHECK(c.mean_response_change < 0.01);
    // The outer ring is gone wherever it was, in air and through the object; the inner one,
    // whose circle never leaves the object, is as training left it.
    const riner::Array inner = ring_inside_only(g);
    double worst = 0.0;
    for (std::size_t p = 0; p < truth.size(); ++p) {
      worst = std::max(worst, std::fabs(double(c.image.data[p]) - truth.data[p] - inner.data[p]));
    }
    CHECK(worst < 1e-6);

    // Same predicted readings: per element, averaged over views, within 3% of the ring's
    // largest projection (~0.005); reading by reading within 5%, because the projector sees
    // the ring's pixels (a staircase of half-pixel bins) where the correction integrates its
    // radial profile.
    const std::vector<double> before = predicted(g, trained, alpha);
    const std::vector<double> after = predicted(g, c.image, c.alpha);
    double largest_ring = 0.0;
    for (std::size_t e = 0; e < g.n_u; ++e) {
      largest_ring = std::max(largest_ring, -std::log(double(c.alpha.data[e]) / alpha.data[e]));
    }
    CHECK(largest_ring > 0.004);
    double mean_mismatch = 0.0;
    double reading_mismatch = 0.0;
    for (std::size_t e = 0; e < g.n_u; ++e) {
      double sum = 0.0;
      for (std::size_t v = 0; v < g.n_views(); ++v) {
        const double d = after[v * g.n_u + e] - before[v * g.n_u + e];
        sum += d;
        reading_mismatch = std::max(reading_mismatch, std::fabs(d));
      }
      mean_mismatch = std::max(mean_mismatch, std::fabs(sum / static_cast<double>(g.n_views())));
    }
    CHECK(mean_mismatch < 0.03 * largest_ring);
    CHECK(reading_mismatch < 0.05 * largest_ring);
  }

  TEST_CASE("an image without air, or with a uniform air level, keeps its values") {
    const riner::Geometry g = ring_geometry();
    riner::Array alpha({g.n_u}, 1.0f);
    riner::Array full(g.volume_shape, 0.02f);
    const riner::AirRingCorrection none = riner::correct_rings_from_air(full, alpha, g);
    CHECK_FALSE(none.applied);
    CHECK(none.measured_radii == 0);
    CHECK(none.image.data == full.data);
    CHECK(none.alpha.data == alpha.data);

    // Air read at 0.0004/mm everywhere (an offset, not a ring): nothing to remove.
    const riner::Array offset = phantom(g, false, 0.0004f);
    const riner::AirRingCorrection c = riner::correct_rings_from_air(offset, alpha, g);
    CHECK(c.measured_radii > 20);
    double largest = 0.0;
    for (double v : c.profile) largest = std::max(largest, std::fabs(v));
    CHECK(largest < 1e-7);
  }

  TEST_CASE("a faint container centred on the axis is an object, not a ring: left alone") {
    // A holder of 0.001/mm (below the air threshold of the dense sample inside it), 55 mm in
    // radius, with two dense spheres: removing it would change the response by ~4% on average
    // (training leaves ~1-2%).
    const riner::Geometry g = ring_geometry();
    riner::Array image(g.volume_shape);
    for (std::size_t i = 0; i < 128; ++i) {
      for (std::size_t k = 0; k < 128; ++k) {
        const riner::Vec3 c =
            riner::voxel_centre(g, static_cast<double>(k), static_cast<double>(i));
        float v = std::hypot(c.x, c.y) < 55.0 ? 0.001f : 0.0f;
        if (std::hypot(c.x - 20.0, c.y) < 8.0 || std::hypot(c.x + 15.0, c.y - 15.0) < 8.0)
          v = 0.04f;
        image(i, k) = v;
      }
    }
    riner::Array alpha({g.n_u}, 1.0f);
    const riner::AirRingCorrection c = riner::correct_rings_from_air(image, alpha, g);
    CHECK(c.measured_radii > 20);
    CHECK(c.mean_response_change > riner::AirRingSettings{}.max_mean_response_change);
    CHECK_FALSE(c.applied);
    CHECK(c.image.data == image.data);
    CHECK(c.alpha.data == alpha.data);
  }

  TEST_CASE("bad input: a 3D geometry, shapes that do not match, non-finite values") {
    const riner::Geometry g = ring_geometry();
    const riner::Array image = phantom(g, true);
    riner::Array alpha({g.n_u}, 1.0f);
    CHECK_THROWS_AS(riner::correct_rings_from_air(image, riner::Array({g.n_u - 1}, 1.0f), g),
                    riner::InputError);
    CHECK_THROWS_AS(riner::correct_rings_from_air(riner::Array({128, 127}), alpha, g),
                    riner::InputError);
    CHECK_THROWS_AS(riner::correct_rings_from_air(image, alpha, riner::test::small_cone3d()),
                    riner::InputError);
    riner::AirRingSettings bad;
    bad.air_fraction = 0.0;
    CHECK_THROWS_AS(riner::correct_rings_from_air(image, alpha, g, bad), riner::InputError);
    riner::Array broken = image;
    broken.data[77] = NAN;
    const riner::AirRingCorrection c = riner::correct_rings_from_air(broken, alpha, g);
    CHECK_FALSE(c.applied);
    CHECK(std::isnan(c.image.data[77]));
    CHECK(c.alpha.data == alpha.data);
  }
}
