// Skipping the air (model/occupancy.hpp): the region carved from the measurements keeps every
// voxel of the object, drops air, gives up without evidence, and clipped rays keep every
// sample inside it, at the same positions.
#include <doctest/doctest.h>

#include <cmath>

#include "model/occupancy.hpp"
#include "riner/phantom.hpp"
#include "riner/simulate.hpp"
#include "support/geometries.hpp"

namespace {

// An off-centre disc and a small ellipse (mu 0.02 / mm) on the geometry's grid.
riner::Phantom discs(const riner::Geometry& g) {
  const double half = 0.5 * g.voxel_mm * static_cast<double>(g.volume_shape.back());
  riner::Phantom p;
  p.ellipsoids.push_back({{0.2 * half, -0.1 * half, 0.0},
                          {0.45 * half, 0.45 * half, 0.4 * half},
                          {1, 0, 0, 0, 1, 0, 0, 0, 1},
                          0.02});
  p.ellipsoids.push_back({{-0.55 * half, 0.4 * half, 0.0},
                          {0.1 * half, 0.2 * half, 0.15 * half},
                          {1, 0, 0, 0, 1, 0, 0, 0, 1},
                          0.03});
  return p;
}

riner::Scan ring_scan(const riner::Geometry& g, const riner::Phantom& p, double photons) {
  riner::RingModel model;
  model.seed = 11;
  model.photons = photons;
  model.dead_elements = 1;
  const riner::Array clean = riner::exact_projections(p, g);
  const riner::Array alpha = riner::draw_responses(g, model);
  return riner::Scan{riner::corrupt_measurement(clean, alpha, model), g, 0};
}

// Every voxel the object touches is inside; returns the object's share of the grid.
double check_object_kept(const riner::model::Occupancy& o, const riner::Array& truth) {
  std::size_t object = 0, lost = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (truth.data[i] <= 0.0f) continue;
    ++object;
    lost += o.inside[i] == 0;
  }
  CHECK(lost == 0);
  return static_cast<double>(object) / static_cast<double>(truth.size());
}

}  // namespace

TEST_SUITE("occupancy") {
  TEST_CASE("rays that read air carve it away; every voxel of the object stays (2D, 3D)") {
    const riner::Geometry geometries[] = {
        riner::test::make_geometry(riner::GeometryType::kParallel2d, 90, 80, 1, {48, 48}, 1.0, 1.0,
                                   M_PI),
        riner::test::small_fan2d(), riner::test::small_cone3d()};
    for (const riner::Geometry& g : geometries) {
      for (double photons : {1e6, 0.0}) {  // noisy, and noise-free (the noise floor)
        CAPTURE(riner::geometry_type_name(g.type));
        CAPTURE(photons);
        const riner::Phantom p = discs(g);
        const riner::Array truth = riner::rasterize(p, g, 2);
        const riner::model::Occupancy o =
            riner::model::carve_occupancy(ring_scan(g, p, photons), {});
        REQUIRE(o.carved);
        CHECK(o.air_elements >= 4);
        CHECK(o.noise > 0.0);
        const double object = check_object_kept(o, truth);
        // Air went: the corners, and most of the grid outside the two shapes' hull.
        CHECK(o.inside[0] == 0);
        CHECK(o.inside_fraction < 0.8);
        CHECK(o.inside_fraction > object);
      }
    }
  }

  TEST_CASE("no element reads only air (the object wider than the detector): nothing carved") {
    const riner::Geometry g = riner::test::make_geometry(riner::GeometryType::kParallel2d, 60, 30,
                                                         1, {48, 48}, 1.0, 1.0, M_PI);
    // A disc centred on the axis projects alike in every view: its readings are as steady as
    // air's. Strong, they are no plausible -ln alpha; faint, they do not average 0.
    for (const auto& [mu, why] : {std::pair<double, const char*>{0.02, "too few detector elements"},
                                  {0.005, "not the 0 of air"}}) {
      CAPTURE(mu);
      riner::Phantom p;
      p.ellipsoids.push_back({{0, 0, 0}, {23, 23, 23}, {1, 0, 0, 0, 1, 0, 0, 0, 1}, mu});
      REQUIRE(g.n_u * g.pitch_u < 2 * 23.0);
      const riner::model::Occupancy o = riner::model::carve_occupancy(ring_scan(g, p, 1e6), {});
      CHECK_FALSE(o.carved);
      CHECK(o.inside_fraction == 1.0);
      CHECK_MESSAGE(o.note.find(why) != std::string::npos, o.note);
      for (std::uint8_t v : o.inside) CHECK(v == 1);
      // Off the axis: no element reads only air either.
      p.ellipsoids[0].centre = {6.0, 0.0, 0.0};
      CHECK_FALSE(riner::model::carve_occupancy(ring_scan(g, p, 1e6), {}).carved);
    }
  }

  TEST_CASE("clipped rays keep every sample inside the region, at the same positions") {
    const riner::Geometry g = riner::test::small_fan2d();
    const riner::Phantom p = discs(g);
    const riner::model::Occupancy o = riner::model::carve_occupancy(ring_scan(g, p, 1e6), {});
    REQUIRE(o.carved);
    const double spacing = 1.5;
    const std::vector<riner::model::RaySegment> full =
        riner::model::ray_segments(g, spacing, false);
    std::vector<riner::model::RaySegment> clipped = full;
    const double kept = riner::model::clip_segments(clipped, g, o, spacing);
    double total = 0.0, inside_samples = 0.0;
    const long n = static_cast<long>(g.volume_shape[1]);
    for (std::size_t r = 0; r < full.size(); ++r) {
      total += full[r].count;
      CHECK(clipped[r].dx == full[r].dx);
      // The clipped run starts at an original sample.
      std::int64_t first = -1;
      if (clipped[r].count > 0) {
        for (std::uint32_t k = 0; k < full[r].count && first < 0; ++k) {
          float a[3], b[3];
          riner::model::sample_position(full[r], k, 0.5f, a);
          riner::model::sample_position(clipped[r], 0, 0.5f, b);
          if (std::fabs(a[0] - b[0]) < 1e-5f && std::fabs(a[1] - b[1]) < 1e-5f) first = k;
        }
        REQUIRE(first >= 0);
      }
      for (std::uint32_t k = 0; k < full[r].count; ++k) {
        float pos[3];
        riner::model::sample_position(full[r], k, 0.5f, pos);
        const long column = std::lround((pos[0] - 0.5) * n + 0.5 * (n - 1));
        const long row = std::lround(0.5 * (n - 1) - (pos[1] - 0.5) * n);
        if (column < 0 || column >= n || row < 0 || row >= n) continue;
        if (!o.inside[static_cast<std::size_t>(row * n + column)]) continue;
        inside_samples += 1.0;
        CHECK(first >= 0);
        CHECK(static_cast<std::int64_t>(k) >= first);
        CHECK(static_cast<std::int64_t>(k) < first + clipped[r].count);
      }
    }
    CHECK(kept < total);
    CHECK(kept >= inside_samples);
  }
}

TEST_SUITE("occupancy output") {
  TEST_CASE("the output ramps to 0 over the region's outer voxels; 0 outside; deep voxels kept") {
    // A 9 x 9 region (rows and columns 2..10) in a 13 x 13 grid; the image is all 3.
    riner::model::Occupancy o;
    o.carved = true;
    o.inside.assign(13 * 13, 0);
    for (int r = 2; r <= 10; ++r)
      for (int c = 2; c <= 10; ++c) o.inside[static_cast<std::size_t>(r * 13 + c)] = 1;
    std::vector<float> image(13 * 13, 3.0f);
    riner::model::fade_into_skipped_air(o, {13, 13}, 2, image);
    auto at = [&](int r, int c) { return image[static_cast<std::size_t>(r * 13 + c)]; };
    CHECK(at(0, 0) == 0.0f);
    CHECK(at(1, 6) == 0.0f);
    CHECK(at(2, 6) == doctest::Approx(1.0));  // outline: depth 1 of 3
    CHECK(at(2, 2) == doctest::Approx(1.0));  // a corner too
    CHECK(at(3, 6) == doctest::Approx(2.0));
    CHECK(at(4, 6) == doctest::Approx(3.0));
    CHECK(at(6, 6) == doctest::Approx(3.0));
    // No taper: a step, as before; and nothing at all without carving.
    std::fill(image.begin(), image.end(), 3.0f);
    riner::model::fade_into_skipped_air(o, {13, 13}, 0, image);
    CHECK(at(2, 6) == 3.0f);
    CHECK(at(1, 6) == 0.0f);
    o.carved = false;
    std::fill(image.begin(), image.end(), 3.0f);
    riner::model::fade_into_skipped_air(o, {13, 13}, 2, image);
    CHECK(at(0, 0) == 3.0f);
    CHECK(riner::model::air_taper_px(4) == 2);
    CHECK(riner::model::air_taper_px(1) == 0);
  }
}
