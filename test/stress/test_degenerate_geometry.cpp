// Degenerate and extreme geometries: a clear error or a correct result, never a crash.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/projector.hpp"
#include "riner/reconstructor.hpp"
#include "support/fixture.hpp"
#include "support/geometries.hpp"

namespace {

riner::Scan ones(const riner::Geometry& g) {
  return {riner::Array(g.measurement_shape(), 0.5f), g, 0};
}

// Either runs to finite results or throws riner::Error; anything else fails the test.
void survives(const riner::Geometry& g) {
  try {
    riner::FbpOptions options;
    options.device = riner::test::device();
    for (float v : riner::fbp(ones(g), options).data) REQUIRE(std::isfinite(v));
    const riner::Projector p(g, riner::Engine::kOpenCL, riner::test::device());
    for (float v : p.project(riner::Array(g.volume_shape, 0.01f)).data) REQUIRE(std::isfinite(v));
    riner::RinerConfig c;
    c.training.steps = 20;
    c.training.rays_per_step = 16;
    riner::Reconstructor r(ones(g), c, riner::test::device());
    r.run();
    for (float v : r.image().data) REQUIRE(std::isfinite(v));
  } catch (const riner::Error& e) {
    MESSAGE((std::string(riner::geometry_type_name(g.type)) + ": " + e.what()));
  }
}

}  // namespace

TEST_SUITE("degenerate_geometry") {
  TEST_CASE("one view, one element, one voxel row") {
    using riner::GeometryType;
    survives(riner::test::make_geometry(GeometryType::kParallel2d, 1, 16, 1, {16, 16}, 1.0, 1.0));
    // One element on the axis reaches nothing of a 16 mm grid: refused, like a unit's mistake.
    CHECK_THROWS_WITH_AS(
        riner::test::make_geometry(GeometryType::kFan2d, 8, 1, 1, {16, 16}, 1.0, 1.0),
        doctest::Contains("the detector's rays reach 0 mm from the axis"), riner::InputError);
    survives(riner::test::make_geometry(GeometryType::kFan2d, 8, 3, 1, {4, 4}, 1.0, 1.0));
    survives(riner::test::make_geometry(GeometryType::kParallel2d, 8, 16, 1, {1, 16}, 1.0, 1.0));
    survives(riner::test::make_geometry(GeometryType::kCone3d, 1, 9, 1, {1, 8, 8}, 1.0, 1.0));
  }

  TEST_CASE("tiny and huge pitch, an offset beyond the field of view") {
    using riner::GeometryType;
    // A pitch of 1 nm: 32 elements cover 0.00001 mm of a 16 mm grid (a pitch in metres).
    CHECK_THROWS_WITH_AS(
        riner::test::make_geometry(GeometryType::kFan2d, 12, 32, 1, {16, 16}, 1e-6, 1.0),
        doctest::Contains("check detector.pitch_mm and volume.voxel_mm"), riner::InputError);
    survives(riner::test::make_geometry(GeometryType::kFan2d, 12, 32, 1, {16, 16}, 0.05, 1.0));
    // A pitch of 1 km: the 16 mm grid lies behind one element.
    CHECK_THROWS_WITH_AS(
        riner::test::make_geometry(GeometryType::kFan2d, 12, 32, 1, {16, 16}, 1e6, 1.0),
        doctest::Contains("narrower than one detector element at the axis"), riner::InputError);
    survives(riner::test::make_geometry(GeometryType::kFan2d, 12, 32, 1, {16, 16}, 10.0, 1.0));
    riner::Geometry off =
        riner::test::make_geometry(GeometryType::kParallel2d, 12, 32, 1, {16, 16}, 1.0, 1.0);
    off.offset_u = 1000.0;
    CHECK_THROWS_WITH_AS(
        riner::Reconstructor(ones(off), riner::RinerConfig(), riner::test::device()),
        doctest::Contains("no detector ray crosses the reconstruction grid"), riner::InputError);
    survives(off);
  }

  TEST_CASE("angles in degrees, a grid narrower than one element: refused with the reason") {
    riner::Geometry g = riner::test::make_geometry(riner::GeometryType::kParallel2d, 180, 32, 1,
                                                   {16, 16}, 1.0, 1.0);
    for (std::size_t i = 0; i < g.angles.size(); ++i) g.angles[i] = static_cast<double>(i);
    CHECK_THROWS_WITH_AS(g.validate(),
                         "the angles reach 179 rad, 28.5 turns: angles are in radians (one turn "
                         "is 6.2832); were degrees given?",
                         riner::InputError);
    g.angles[179] = 1e300;  // a start angle of 1e300 made every view the same
    CHECK_THROWS_WITH_AS(g.validate(), doctest::Contains("the angles reach 1e+300 rad"),
                         riner::InputError);
    // 16 turns of a multi-turn scan pass.
    for (std::size_t i = 0; i < g.angles.size(); ++i) g.angles[i] = 0.55 * static_cast<double>(i);
    CHECK_NOTHROW(g.validate());
    CHECK_THROWS_WITH_AS(
        riner::test::make_geometry(riner::GeometryType::kFan2d, 12, 32, 1, {16, 16}, 2.0, 1e-9),
        doctest::Contains("the grid is 1.6e-08 mm wide, narrower than one "
                          "detector element at the axis"),
        riner::InputError);
  }

  TEST_CASE("a source inside the volume is refused with the reason") {
    riner::Geometry g =
        riner::test::make_geometry(riner::GeometryType::kFan2d, 12, 32, 1, {64, 64}, 1.0, 1.0);
    g.source_origin_mm = 20.0;
    CHECK_THROWS_WITH_AS(g.validate(),
                         doctest::Contains("puts the source inside the reconstruction grid"),
                         riner::InputError);
    CHECK_THROWS_AS(riner::fbp(ones(g)), riner::InputError);
    CHECK_THROWS_AS(riner::Reconstructor(ones(g), riner::RinerConfig(), riner::test::device()),
                    riner::InputError);
  }
}
