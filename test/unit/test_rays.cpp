// Ray generation and clipping against hand-computed geometry.
#include <doctest/doctest.h>

#include <cmath>

#include "riner/rays.hpp"
#include "support/geometries.hpp"

namespace {

riner::Geometry fan_paper_like() {
  auto g = riner::test::make_geometry(riner::GeometryType::kFan2d, 4, 5, 1, {8, 8}, 2.0, 1.0);
  g.source_origin_mm = 370.0;
  g.origin_detector_mm = 370.0;
  g.angles = {0.0, M_PI / 2, M_PI, 1.0};
  return g;
}

}  // namespace

TEST_SUITE("rays") {
  TEST_CASE("fan beam: source, detector and central ray follow the convention") {
    const riner::Geometry g = fan_paper_like();
    // View 0: source at (0, -SOD), detector centre at (0, ODD), u along +x.
    riner::Ray r = riner::detector_ray(g, 0, 2.0);  // the centre element of 5
    CHECK(r.origin.x == doctest::Approx(0.0));
    CHECK(r.origin.y == doctest::Approx(-370.0));
    CHECK(r.direction.x == doctest::Approx(0.0));
    CHECK(r.direction.y == doctest::Approx(1.0));
    riner::Vec3 d = riner::detector_position(g, 0, 4.0);  // two elements right of centre
    CHECK(d.x == doctest::Approx(4.0));
    CHECK(d.y == doctest::Approx(370.0));
    // View pi/2: everything rotated by 90 degrees counter-clockwise.
    r = riner::detector_ray(g, 1, 2.0);
    CHECK(r.origin.x == doctest::Approx(370.0));
    CHECK(r.origin.y == doctest::Approx(0.0).epsilon(1e-9));
    CHECK(r.direction.x == doctest::Approx(-1.0));
    d = riner::detector_position(g, 1, 4.0);
    CHECK(d.x == doctest::Approx(-370.0));
    CHECK(d.y == doctest::Approx(4.0));
    // A detector offset shifts every element along u by offset * pitch.
    riner::Geometry shifted = g;
    shifted.offset_u = 0.5;
    CHECK(riner::detector_position(shifted, 0, 2.0).x == doctest::Approx(1.0));
  }

  TEST_CASE("parallel beam: rays along R(theta)(0, 1) through the element's u position") {
    auto g =
        riner::test::make_geometry(riner::GeometryType::kParallel2d, 2, 4, 1, {4, 4}, 1.0, 1.0);
    g.angles = {0.0, M_PI / 4};
    const riner::Ray r = riner::detector_ray(g, 1, 3.0);  // u = 1.5 mm
    CHECK(r.direction.x == doctest::Approx(-std::sqrt(0.5)));
    CHECK(r.direction.y == doctest::Approx(std::sqrt(0.5)));
    CHECK(r.origin.x == doctest::Approx(1.5 * std::sqrt(0.5)));
    CHECK(r.origin.y == doctest::Approx(1.5 * std::sqrt(0.5)));
  }

  TEST_CASE("cone beam: rows run along z with their own pitch and offset") {
    auto g = riner::test::make_geometry(riner::GeometryType::kCone3d, 1, 3, 5, {4, 8, 8}, 2.0, 1.0);
    g.pitch_v = 3.0;
    g.offset_v = 1.0;
    g.angles = {0.0};
    const riner::Vec3 d = riner::detector_position(g, 0, 1.0, 4.0);
    CHECK(d.z == doctest::Approx((4.0 - 2.0 + 1.0) * 3.0));
    CHECK(d.x == doctest::Approx(0.0));
  }

  TEST_CASE("box clipping: axis-aligned, diagonal, missing and grazing rays") {
    auto g =
        riner::test::make_geometry(riner::GeometryType::kParallel2d, 1, 4, 1, {10, 20}, 1.0, 0.5);
    // The box is |x| <= 5 mm, |y| <= 2.5 mm.
    riner::Ray along_y{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
    CHECK(riner::clip_to_box(g, along_y).length() == doctest::Approx(5.0));
    riner::Ray along_x{{0.0, -1.0, 0.0}, {1.0, 0.0, 0.0}};
    riner::Segment s = riner::clip_to_box(g, along_x);
    CHECK(s.enter == doctest::Approx(-5.0));
    CHECK(s.exit == doctest::Approx(5.0));
    const double h = std::sqrt(0.5);
    riner::Ray diagonal{{0.0, 0.0, 0.0}, {h, h, 0.0}};
    CHECK(riner::clip_to_box(g, diagonal).length() == doctest::Approx(2.0 * 2.5 / h));
    riner::Ray outside{{0.0, 3.0, 0.0}, {1.0, 0.0, 0.0}};
    CHECK(riner::clip_to_box(g, outside).empty());
    // Cylinder: radius min(10, 20) * 0.5 / 2 = 2.5 mm.
    CHECK(riner::clip_to_cylinder(g, along_x).length() ==
          doctest::Approx(2.0 * std::sqrt(2.5 * 2.5 - 1.0)));
    riner::Ray far{{0.0, 2.6, 0.0}, {1.0, 0.0, 0.0}};
    CHECK(riner::clip_to_cylinder(g, far).empty());
  }

  TEST_CASE("3D clipping respects the slab in z") {
    auto g = riner::test::make_geometry(riner::GeometryType::kParallel3d, 1, 4, 4, {4, 10, 10}, 1.0,
                                        1.0);
    // |z| <= 2: a ray rising at 45 degrees leaves through the top after 2 sqrt(2) * 2 mm.
    const double h = std::sqrt(0.5);
    riner::Ray rising{{0.0, 0.0, 0.0}, {0.0, h, h}};
    CHECK(riner::clip_to_box(g, rising).length() == doctest::Approx(4.0 / h));
    CHECK(riner::clip_to_cylinder(g, rising).length() == doctest::Approx(4.0 / h));
    riner::Ray above{{0.0, 0.0, 2.5}, {1.0, 0.0, 0.0}};
    CHECK(riner::clip_to_box(g, above).empty());
  }

  TEST_CASE("voxel centres: row 0 at the top, slice 0 at the bottom") {
    auto g =
        riner::test::make_geometry(riner::GeometryType::kParallel3d, 1, 4, 4, {3, 4, 5}, 1.0, 2.0);
    const riner::Vec3 c = riner::voxel_centre(g, 0, 0, 0);
    CHECK(c.x == doctest::Approx(-4.0));
    CHECK(c.y == doctest::Approx(3.0));
    CHECK(c.z == doctest::Approx(-2.0));
  }
}
