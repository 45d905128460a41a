#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "riner/error.hpp"
#include "riner/geometry.hpp"
#include "support/fixture.hpp"

namespace {

const char* kFan = R"({
  "type": "fan2d",
  "detector": {"count": 500, "pitch_mm": 2.0, "offset_px": 0.0},
  "source_origin_mm": 370.0,
  "origin_detector_mm": 370.0,
  "angles": {"count": 360, "start_rad": 0.0, "range_rad": 6.283185307179586},
  "volume": {"shape": [256, 256], "voxel_mm": 1.0}
})";

const char* kCone = R"({
  "type": "cone3d",
  "detector": {"count": [300, 200], "pitch_mm": [2.0, 2.0], "offset_px": [0.5, -1.0]},
  "source_origin_mm": 300.0,
  "origin_detector_mm": 300.0,
  "angles_rad": [0.0, 0.5, 1.0],
  "volume": {"shape": [100, 256, 256], "voxel_mm": 1.0}
})";

// Replaces the first occurrence of `from` in the fan-beam example.
std::string fan_with(const std::string& from, const std::string& to) {
  std::string text = kFan;
  const auto pos = text.find(from);
  REQUIRE(pos != std::string::npos);
  return text.replace(pos, from.size(), to);
}

void check_error(const std::string& json, const std::string& expected) {
  try {
    riner::Geometry::from_json(json, "g.json");
    FAIL("accepted a bad geometry; expected: " << expected);
  } catch (const riner::InputError& e) {
    CHECK(std::string(e.what()) == expected);
  }
}

}  // namespace

TEST_SUITE("geometry_json") {
  TEST_CASE("the METHOD.md fan-beam example parses exactly") {
    const riner::Geometry g = riner::Geometry::from_json(kFan);
    CHECK(g.type == riner::GeometryType::kFan2d);
    CHECK(g.n_u == 500);
    CHECK(g.pitch_u == 2.0);
    CHECK(g.source_origin_mm == 370.0);
    REQUIRE(g.n_views() == 360);
    CHECK(g.angles[0] == 0.0);
    // Endpoint excluded: 360 views over 2 pi never repeat a view.
    CHECK(g.angles[359] == doctest::Approx(2 * M_PI * 359 / 360));
    CHECK(g.measurement_shape() == std::vector<std::size_t>{360, 500});
  }

  TEST_CASE("3D pairs and explicit angle lists") {
    const riner::Geometry g = riner::Geometry::from_json(kCone);
    CHECK(g.is_3d());
    CHECK(g.n_u == 300);
    CHECK(g.n_v == 200);
    CHECK(g.offset_v == -1.0);
    CHECK(g.angles == std::vector<double>{0.0, 0.5, 1.0});
    CHECK(g.measurement_shape() == std::vector<std::size_t>{3, 200, 300});
  }

  TEST_CASE("to_json round-trips") {
    for (const char* text : {kFan, kCone}) {
      const riner::Geometry g = riner::Geometry::from_json(text);
      const riner::Geometry h = riner::Geometry::from_json(g.to_json());
      CHECK(h.to_json() == g.to_json());
      CHECK(h.angles == g.angles);
      CHECK(h.n_u == g.n_u);
      CHECK(h.offset_v == g.offset_v);
    }
  }

  TEST_CASE("a grid's height on the axis: parsed, round-tripped, checked") {
    std::string raised = kCone;
    const std::string voxel = "\"voxel_mm\": 1.0";
    raised.replace(raised.find(voxel), voxel.size(), voxel + ", \"centre_z_mm\": -12.5");
    const riner::Geometry g = riner::Geometry::from_json(raised);
    CHECK(g.grid_centre_z_mm == -12.5);
    CHECK(riner::Geometry::from_json(g.to_json()).grid_centre_z_mm == -12.5);
    // Absent when 0, so every other geometry's JSON reads as before.
    CHECK(riner::Geometry::from_json(kCone).to_json().find("centre_z_mm") == std::string::npos);
    check_error(fan_with("\"voxel_mm\": 1.0", "\"voxel_mm\": 1.0, \"centre_z_mm\": 3"),
                "g.json: volume.centre_z_mm belongs to a 3D geometry");
    riner::Geometry bad = g;
    bad.grid_centre_z_mm = NAN;
    CHECK_THROWS_WITH_AS(bad.validate(), "volume.centre_z_mm must be finite", riner::InputError);
    // A grid far up the axis, or rows offset far up: no row's rays pass its height (FBP gave
    // zeros). The highest row sits 197 mm up the detector; its rays climb to 158 mm within the
    // grid's circle, so a grid 100 mm high centred 140 mm up is crossed, one at 250 mm is not.
    const std::string kRows = "no detector row's rays cross the reconstruction grid";
    riner::Geometry high = g;
    high.grid_centre_z_mm = 140.0;
    CHECK_NOTHROW(high.validate());
    high.grid_centre_z_mm = 250.0;
    CHECK_THROWS_WITH_AS(high.validate(), doctest::Contains(kRows.c_str()), riner::InputError);
    riner::Geometry lifted = riner::Geometry::from_json(kCone);
    lifted.offset_v = 1e4;
    CHECK_THROWS_WITH_AS(lifted.validate(), doctest::Contains(kRows.c_str()), riner::InputError);
    lifted.type = riner::GeometryType::kParallel3d;
    CHECK_THROWS_WITH_AS(lifted.validate(), doctest::Contains(kRows.c_str()), riner::InputError);
    lifted.offset_v = 0.0;
    CHECK_NOTHROW(lifted.validate());
  }

  TEST_CASE("every bad field is named") {
    try {
      riner::Geometry::from_json("{", "g.json");
      FAIL("accepted truncated JSON");
    } catch (const riner::InputError& e) {
      CHECK(std::string(e.what()).rfind("g.json: invalid JSON: ", 0) == 0);
    }
    check_error("[]", "g.json: top level must be a JSON object");
    check_error(fan_with("\"fan2d\"", "\"fan\""),
                "g.json: type must be one of parallel2d, fan2d, cone3d, parallel3d (got \"fan\")");
    check_error(fan_with("\"count\": 500", "\"count\": 0"),
                "g.json: detector.count must be >= 1 (got 0)");
    check_error(fan_with("\"count\": 500", "\"count\": 2.5"),
                "g.json: detector.count must be a positive integer");
    check_error(fan_with("\"count\": 500", "\"count\": [500, 2]"),
                "g.json: detector.count must be a single value in 2D");
    check_error(fan_with("\"pitch_mm\": 2.0", "\"pitch_mm\": -2"),
                "g.json: detector.pitch_mm must be > 0 (got -2)");
    check_error(fan_with("\"pitch_mm\": 2.0", "\"pitch_mm\": \"2\""),
                "g.json: detector.pitch_mm must be a number");
    check_error(fan_with("\"source_origin_mm\": 370.0,", ""),
                "g.json: source_origin_mm is missing");
    check_error(fan_with("\"origin_detector_mm\": 370.0", "\"origin_detector_mm\": 0"),
                "g.json: origin_detector_mm must be > 0 (got 0)");
    check_error(fan_with("\"source_origin_mm\": 370.0", "\"source_origin_mm\": 100"),
                "g.json: source_origin_mm (100.000000) puts the source inside the reconstruction "
                "grid (half-diagonal 181.019336 mm)");
    check_error(fan_with("\"count\": 360", "\"count\": -4"),
                "g.json: angles.count must be >= 1 (got -4)");
    check_error(fan_with("\"range_rad\": 6.283185307179586", "\"range_rad\": 0"),
                "g.json: angles.range_rad must not be 0");
    check_error(fan_with("\"angles\"", "\"angles_rad\": [0.1], \"angles\""),
                "g.json: angles must be given once: either \"angles\" or \"angles_rad\"");
    check_error(fan_with("[256, 256]", "[256]"),
                "g.json: volume.shape must be [n_y, n_x] for a 2D geometry");
    check_error(fan_with("\"voxel_mm\": 1.0", "\"voxel_mm\": 0"),
                "g.json: volume.voxel_mm must be > 0 (got 0)");
    // A misspelt field is named, not left out (the offset would silently be 0).
    check_error(fan_with("\"volume\"", "\"volumes\""),
                "g.json: volumes is not a geometry field (the file takes type, detector, "
                "source_origin_mm, origin_detector_mm, angles, angles_rad, volume, files)");
    check_error(fan_with("\"offset_px\"", "\"offset\""),
                "g.json: detector.offset is not a geometry field (detector takes count, "
                "pitch_mm, offset_px)");
    check_error(fan_with("\"voxel_mm\": 1.0", "\"voxel_mm\": 1.0, \"center_z_mm\": 20"),
                "g.json: volume.center_z_mm is not a geometry field (volume takes shape, "
                "voxel_mm, centre_z_mm)");
    check_error(fan_with("\"start_rad\"", "\"start\""),
                "g.json: angles.start is not a geometry field (angles takes count, start_rad, "
                "range_rad)");
    // A parallel beam with a source's distances: another geometry's (they were dropped).
    check_error(fan_with("\"fan2d\"", "\"parallel2d\""),
                "g.json: source_origin_mm belongs to a fan or cone beam (type \"fan2d\" or "
                "\"cone3d\"); a parallel beam has none");
    // Every view at one angle (FBP drew streaks with only a warning).
    check_error(fan_with("\"angles\": {\"count\": 360, \"start_rad\": 0.0, \"range_rad\": "
                         "6.283185307179586}",
                         "\"angles_rad\": [0.5, 0.5, 0.5]"),
                "g.json: angles: all 3 views are at one angle (0.500000 rad): a scan turns the "
                "object");
    // NaN, as Python's json.dump writes it, is named as no JSON number.
    try {
      riner::Geometry::from_json(fan_with("\"start_rad\": 0.0", "\"start_rad\": NaN"), "g.json");
      FAIL("accepted NaN");
    } catch (const riner::InputError& e) {
      CHECK(std::string(e.what()).find("NaN and Infinity are no JSON numbers") !=
            std::string::npos);
    }
    // Documentation is not a field.
    CHECK_NOTHROW(riner::Geometry::from_json(
        fan_with("\"type\"", "\"comment\": \"scanner A\", \"_source\": 1, \"type\""), "g.json"));
    // The detector shifted off the grid: every ray misses it (FBP gave an image of zeros).
    check_error(
        fan_with("\"offset_px\": 0.0", "\"offset_px\": 600"),
        "g.json: no detector ray crosses the reconstruction grid: the rays pass 254.5 mm or "
        "more from the axis, the grid reaches 181 mm (check detector.offset_px, pitch_mm "
        "and volume.voxel_mm)");
  }

  TEST_CASE("a key given twice in one object is refused; the same key in sibling objects is not") {
    // Before: the last one won without a word (a geometry's "detector", a config's "steps").
    const std::string twice = R"({"type": "parallel2d", "detector": {"count": 8, "pitch_mm": 1},
      "detector": {"count": 4, "pitch_mm": 1}, "angles": {"count": 3, "range_rad": 3.14},
      "volume": {"shape": [8, 8], "voxel_mm": 1}})";
    CHECK_THROWS_WITH_AS(riner::Geometry::from_json(twice, "g.json"),
                         "g.json: the key \"detector\" appears twice in one object (which one "
                         "is meant?)",
                         riner::InputError);
    const std::string siblings = R"({"type": "parallel2d", "detector": {"count": 8, "pitch_mm": 1},
      "angles": {"count": 3, "range_rad": 3.14}, "volume": {"shape": [8, 8], "voxel_mm": 1}})";
    CHECK(riner::Geometry::from_json(siblings, "g.json").n_u == 8);
  }

  TEST_CASE("measurement shape mismatch names both shapes and the view count") {
    const riner::Geometry g = riner::Geometry::from_json(kFan);
    CHECK_NOTHROW(g.check_measurement_shape({360, 500}));
    CHECK_THROWS_WITH_AS(g.check_measurement_shape({359, 500}, "sino.npy"),
                         "sino.npy has shape [359, 500] but the fan2d geometry expects [360, 500] "
                         "[views, elements]: it has 359 views but the geometry lists 360 angles",
                         riner::InputError);
    CHECK_THROWS_AS(g.check_measurement_shape({360, 500, 1}), riner::InputError);
  }

  TEST_CASE("the shared real-scan geometries parse") {
    for (const char* name :
         {"neutron360", "wood_neutron", "htc2022_disc", "tooth", "savu_proj3d"}) {
      const auto path = riner::test::shared_data(std::string(name) + "/geometry.json");
      if (path.empty()) continue;
      CAPTURE(name);
      const riner::Geometry g = riner::Geometry::load(path);
      CHECK(g.n_views() > 0);
    }
  }
}
