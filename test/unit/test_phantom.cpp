// Phantom line integrals and rasters against closed forms.
#include <doctest/doctest.h>

#include <cmath>

#include "riner/error.hpp"
#include "riner/phantom.hpp"
#include "support/geometries.hpp"

TEST_SUITE("phantom") {
  TEST_CASE("a disk: chord lengths and area") {
    riner::Phantom disk;
    riner::Ellipsoid e;
    e.semi_axes = {10.0, 10.0, 1.0};
    e.value = 0.5;
    disk.ellipsoids.push_back(e);
    for (double offset : {0.0, 3.0, 9.9}) {
      const riner::Ray ray{{-50.0, offset, 0.0}, {1.0, 0.0, 0.0}};
      CHECK(disk.line_integral(ray) ==
            doctest::Approx(0.5 * 2.0 * std::sqrt(100.0 - offset * offset)));
    }
    CHECK(disk.line_integral({{-50.0, 10.5, 0.0}, {1.0, 0.0, 0.0}}) == 0.0);
    // Raster on a 1 mm grid: the mean equals value * area / grid area to supersampling error.
    const riner::Geometry g =
        riner::test::make_geometry(riner::GeometryType::kParallel2d, 1, 4, 1, {32, 32}, 1.0, 1.0);
    const riner::Array raster = riner::rasterize(disk, g, 8);
    double sum = 0.0;
    for (float v : raster.data) sum += v;
    CHECK(sum == doctest::Approx(0.5 * M_PI * 100.0).epsilon(2e-3));
  }

  TEST_CASE("rotated ellipse: value_at and line integral agree") {
    riner::Phantom p;
    riner::Ellipsoid e;
    e.centre = {3.0, -2.0, 0.0};
    e.semi_axes = {8.0, 3.0, 1.0};
    const double phi = 0.4;
    e.rotation = {std::cos(phi), std::sin(phi), 0, -std::sin(phi), std::cos(phi), 0, 0, 0, 1};
    e.value = 1.0;
    p.ellipsoids.push_back(e);
    // Along the ellipse's major axis the chord is 2 a = 16.
    const riner::Ray major{{3.0 - 30 * std::cos(phi), -2.0 - 30 * std::sin(phi), 0.0},
                           {std::cos(phi), std::sin(phi), 0.0}};
    CHECK(p.line_integral(major) == doctest::Approx(16.0));
    // A numerical integral of value_at along an arbitrary line matches.
    const riner::Ray ray{{-20.0, -9.0, 0.0}, {0.8, 0.6, 0.0}};
    double numeric = 0.0;
    const double dt = 1e-3;
    for (double t = 0.0; t < 60.0; t += dt) {
      numeric += p.value_at({ray.origin.x + t * 0.8, ray.origin.y + t * 0.6, 0.0}) * dt;
    }
    CHECK(p.line_integral(ray) == doctest::Approx(numeric).epsilon(1e-3));
  }

  TEST_CASE("Shepp-Logan fits the grid and has its known contrasts") {
    const riner::Geometry g =
        riner::test::make_geometry(riner::GeometryType::kFan2d, 1, 64, 1, {128, 128}, 2.0, 1.0);
    const riner::Phantom p = riner::shepp_logan(g, 0.1);
    CHECK(p.value_at({0.0, 0.0, 0.0}) == doctest::Approx(0.02));  // brain: (1 - 0.8) * 0.1
    // Skull at x = 0 between the brain's top (52.0 mm) and the head's (55.9 mm): 1.0 * 0.1.
    CHECK(p.value_at({0.0, 54.0, 0.0}) == doctest::Approx(0.1));
    CHECK(p.value_at({64.0, 0.0, 0.0}) == 0.0);  // outside the head
    // A negative scale simulated a beam brightened past float's range (64 319 non-finite).
    CHECK_THROWS_WITH_AS(riner::shepp_logan(g, -1.0),
                         "the Shepp-Logan's mu scale must be finite and > 0 (got -1)",
                         riner::InputError);
    CHECK_THROWS_AS(riner::shepp_logan(g, NAN), riner::InputError);
  }

  TEST_CASE("the tube wall: its wall about the axis, its content and the water around it") {
    const riner::Geometry g =
        riner::test::make_geometry(riner::GeometryType::kFan2d, 1, 64, 1, {256, 256}, 2.0, 1.0);
    const riner::Phantom p = riner::tube_wall(g);
    const riner::TubeWallShape t = riner::tube_wall_shape(g);
    CHECK(t.inner_mm == doctest::Approx(59.904));
    CHECK(t.outer_mm == doctest::Approx(66.048));
    const double mid = 0.5 * (t.inner_mm + t.outer_mm);
    for (double phi = 0.0; phi < 2.0 * M_PI; phi += 0.7) {  // the same all the way round
      CHECK(p.value_at({mid * std::cos(phi), mid * std::sin(phi), 0.0}) == doctest::Approx(t.wall));
    }
    CHECK(p.value_at({0.0, 40.0, 0.0}) == doctest::Approx(t.inside));
    CHECK(p.value_at({0.0, -80.0, 0.0}) == doctest::Approx(t.water));
    CHECK(p.value_at({0.0, 120.0, 0.0}) == 0.0);
    // The ray just outside the wall's outer tangent crosses only water: a chord of the
    // water disc.
    const riner::Ray tangent{{-200.0, t.outer_mm + 1e-6, 0.0}, {1.0, 0.0, 0.0}};
    const double water = 2.0 * std::sqrt(std::pow(0.39 * 256.0, 2) - t.outer_mm * t.outer_mm);
    CHECK(p.line_integral(tangent) == doctest::Approx(water * t.water).epsilon(1e-6));
  }
}
