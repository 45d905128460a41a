// What the readings say against the geometry. Whether the views turn as far as the angles say:
// scans of half and full turns read as they are, the same scans under angles of the other range
// (a 360-degree scan given 180 degrees, and the reverse) caught, objects that cannot tell (a disc
// on the axis) left undecided. Whether a fan's distances pair its rays with their conjugates.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "riner/angular_range.hpp"
#include "riner/centre.hpp"
#include "riner/error.hpp"
#include "riner/geometry_doubts.hpp"
#include "riner/projector.hpp"
#include "support/asymmetric_object.hpp"
#include "support/geometries.hpp"

namespace {

using riner::test::with_angles;

riner::Scan scan_of(const riner::Geometry& g, const riner::Array& object) {
  g.validate();
  return {riner::Projector(g, riner::Engine::kReference).project(object), g, 0};
}

// The same readings under angles scaled by `factor` about the first.
riner::Scan relabelled(riner::Scan s, double factor) {
  s.geometry.uniform_angles.reset();
  const double first = s.geometry.angles.front();
  for (double& a : s.geometry.angles) a = first + factor * (a - first);
  return s;
}

// Each element offset by its own constant, up to `share` of the largest reading either way, and
// Gaussian noise of `noise` of it: a ringed, noisy detector.
riner::Scan ringed(riner::Scan s, double share, double noise) {
  double top = 0.0;
  for (float v : s.measurement.data) top = std::max(top, static_cast<double>(v));
  const std::size_t per_view = s.measurement.size() / s.geometry.n_views();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> offset(-share * top, share * top);
  std::normal_distribution<double> gauss(0.0, noise * top);
  std::vector<double> stripes(per_view);
  for (double& o : stripes) o = offset(rng);
  for (std::size_t i = 0; i < s.measurement.size(); ++i) {
    s.measurement.data[i] += static_cast<float>(stripes[i % per_view] + gauss(rng));
  }
  return s;
}

}  // namespace

TEST_SUITE("angular range") {
  TEST_CASE("half and full turns read as their angles say; under the other range, a doubt") {
    const riner::Geometry base = riner::test::small_parallel2d();
    const riner::Array object = riner::test::asymmetric_object(base.volume_shape);
    struct Case {
      std::size_t views;
      double range;
      bool endpoint;
      riner::TurnReading turn;
    };
    for (const Case& c : {Case{61, M_PI, true, riner::TurnReading::kHalfTurn},
                          Case{60, M_PI, false, riner::TurnReading::kHalfTurn},
                          Case{90, 2.0 * M_PI, false, riner::TurnReading::kFullTurn},
                          Case{91, 2.0 * M_PI, true, riner::TurnReading::kFullTurn}}) {
      for (const double rings : {0.0, 0.1}) {
        CAPTURE(c.views);
        CAPTURE(rings);
        const riner::Scan scan =
            ringed(scan_of(with_angles(base, c.views, c.range, c.endpoint), object), rings, 0.002);
        const riner::AngularRangeEvidence as_given = riner::read_angular_range(scan);
        CHECK(as_given.geometry == c.turn);
        CHECK(as_given.readings == c.turn);
        CHECK_FALSE(riner::angular_range_doubt(as_given));

        const bool full = c.turn == riner::TurnReading::kFullTurn;
        const riner::Scan wrong = relabelled(scan, full ? 0.5 : 2.0);
        const riner::AngularRangeEvidence e = riner::read_angular_range(wrong);
        CHECK(e.geometry != c.turn);
        CHECK(e.readings == c.turn);
        const std::optional<std::string> doubt = riner::angular_range_doubt(e);
        REQUIRE(doubt);
        CHECK(doubt->find(full ? "the views cover a full turn (360 degrees)"
                               : "the views cover a half-turn (180 degrees)") == 0);
        CHECK(doubt->find("check the geometry's angles") != std::string::npos);
        // The centre finders pair views by the angles: they stop instead of answering.
        CHECK_THROWS_WITH_AS(riner::estimate_centre(wrong), doctest::Contains("no centre: "),
                             riner::InputError);
      }
    }
  }

  TEST_CASE("parallel 3D: the rows read together") {
    const riner::Geometry g = with_angles(riner::test::small_parallel3d(), 40, 2.0 * M_PI, false);
    const riner::Scan scan = scan_of(g, riner::test::asymmetric_object(g.volume_shape));
    CHECK(riner::read_angular_range(scan).readings == riner::TurnReading::kFullTurn);
    CHECK_FALSE(riner::angular_range_doubt(scan));
    CHECK(riner::angular_range_doubt(relabelled(scan, 0.5)));
  }

  TEST_CASE("a disc on the axis looks the same at every angle: undecided, no doubt") {
    const riner::Geometry g = with_angles(riner::test::small_parallel2d(), 90, 2.0 * M_PI, false);
    riner::Array disc(g.volume_shape);
    const std::size_t ny = g.volume_shape[0], nx = g.volume_shape[1];
    for (std::size_t i = 0; i < ny; ++i) {
      for (std::size_t k = 0; k < nx; ++k) {
        const double x = static_cast<double>(k) - 0.5 * (nx - 1.0);
        const double y = static_cast<double>(i) - 0.5 * (ny - 1.0);
        disc.data[i * nx + k] = std::hypot(x, y) < 20.0 ? 0.02f : 0.0f;
      }
    }
    const riner::Scan scan = ringed(scan_of(g, disc), 0.1, 0.002);
    for (const double factor : {1.0, 0.5}) {
      CAPTURE(factor);
      const riner::AngularRangeEvidence e = riner::read_angular_range(relabelled(scan, factor));
      CHECK(e.readings == riner::TurnReading::kUndecided);
      CHECK_FALSE(riner::angular_range_doubt(e));
    }
  }

  TEST_CASE("not checked: a fan beam, a range of neither turn, too few views") {
    const riner::Geometry fan = riner::test::small_fan2d();
    const riner::Array object = riner::test::asymmetric_object(fan.volume_shape);
    CHECK(riner::read_angular_range(scan_of(fan, object)).geometry ==
          riner::TurnReading::kNotChecked);
    const riner::Geometry base = riner::test::small_parallel2d();
    const riner::Array parallel_object = riner::test::asymmetric_object(base.volume_shape);
    for (const auto& [views, degrees] :
         {std::pair{60, 120.0}, std::pair{60, 270.0}, std::pair{6, 180.0}}) {
      CAPTURE(views);
      CAPTURE(degrees);
      const riner::Scan scan =
          scan_of(with_angles(base, static_cast<std::size_t>(views), degrees * M_PI / 180.0, false),
                  parallel_object);
      const riner::AngularRangeEvidence e = riner::read_angular_range(scan);
      CHECK(e.readings == riner::TurnReading::kNotChecked);
      CHECK_FALSE(riner::angular_range_doubt(e));
    }
  }
}

TEST_SUITE("fan geometry") {
  // The fan's distances and sense against its conjugate rays: the scan under its own geometry,
  // then under the source-detector distance given as origin_detector_mm (TIGRE's DSD where
  // riner wants the axis-detector distance), under twice its pitch (a detector binned 2x, the
  // pitch not), and turning the other way.
  TEST_CASE("a fan and a cone: a wrong distance, pitch or sense is doubted, the right ones not") {
    // The cone with three times the small cone's views: at 9 degrees a step its conjugates,
    // read between views, miss by as much as a wrong distance's (3x, under the 4x asked).
    const riner::Geometry cone = riner::test::make_geometry(riner::GeometryType::kCone3d, 120, 61,
                                                            37, {24, 40, 40}, 1.5, 1.0);
    for (const riner::Geometry& g : {riner::test::small_fan2d(), cone}) {
      CAPTURE(riner::geometry_type_name(g.type));
      const riner::Scan scan =
          ringed(scan_of(g, riner::test::asymmetric_object(g.volume_shape)), 0.1, 0.002);
      CHECK_FALSE(riner::fan_geometry_doubt(scan));
      CHECK(riner::geometry_doubts(scan).empty());
      const double sdd = g.source_origin_mm + g.origin_detector_mm;
      riner::Scan as_sdd = scan;
      as_sdd.geometry.origin_detector_mm = sdd;
      riner::Scan binned = scan;
      binned.geometry.pitch_u = 2.0 * g.pitch_u;
      binned.geometry.pitch_v = 2.0 * g.pitch_v;
      for (const auto& [wrong, factor] :
           {std::pair{as_sdd, sdd / (g.source_origin_mm + sdd)}, std::pair{binned, 2.0}}) {
        CAPTURE(factor);
        const std::optional<std::string> doubt = riner::fan_geometry_doubt(wrong);
        REQUIRE(doubt);
        // "..., F times the geometry's": F within 2% of the truth.
        const std::size_t at = doubt->find(" times the geometry's");
        REQUIRE(at != std::string::npos);
        const double found = std::stod(doubt->substr(doubt->rfind(", ", at) + 2));
        CHECK(found == doctest::Approx(factor).epsilon(0.02));
        CHECK(riner::geometry_doubts(wrong) == std::vector<std::string>{*doubt});
        // The axis stands: its offset's search reads the geometry's distances near the axis.
        CHECK(std::fabs(riner::estimate_centre(wrong).offset_px - g.offset_u) < 0.5);
      }
      // Turned the other way: the angles negated, or the detector's columns reversed.
      riner::Scan reversed = scan;
      reversed.geometry.uniform_angles.reset();
      for (double& a : reversed.geometry.angles) a = -a;
      riner::Scan flipped = scan;
      const std::size_t n_u = g.n_u;
      for (std::size_t line = 0; line < flipped.measurement.size() / n_u; ++line) {
        float* row = flipped.measurement.ptr() + line * n_u;
        std::reverse(row, row + n_u);
      }
      for (const riner::Scan& wrong : {reversed, flipped}) {
        const std::optional<std::string> doubt = riner::fan_geometry_doubt(wrong);
        REQUIRE(doubt);
        CHECK(doubt->find("with the views turning the other way") != std::string::npos);
        // The centre finder's conjugates would pair the wrong way round: no answer.
        CHECK_THROWS_WITH_AS(riner::estimate_centre(wrong),
                             doctest::Contains("no centre: the fan's rays meet their conjugates"),
                             riner::InputError);
      }
    }
  }

  TEST_CASE("a cone whose source plane projects off its rows: no fan read, no centre") {
    // A band of rows cut off the middle of a cone's detector: the rows read as the source's
    // plane were an edge row (a wrong distance said of a right geometry, the axis 2.9 px off).
    riner::Geometry g = riner::test::make_geometry(riner::GeometryType::kCone3d, 120, 61, 37,
                                                   {24, 40, 40}, 1.5, 1.0);
    g.offset_v = -30.0;
    const riner::Scan scan = scan_of(g, riner::test::asymmetric_object(g.volume_shape));
    CHECK_FALSE(riner::fan_geometry_doubt(scan));
    CHECK_THROWS_WITH_AS(riner::estimate_centre(scan),
                         doctest::Contains("the source's plane projects off the detector's rows"),
                         riner::InputError);
  }

  TEST_CASE("a parallel beam and a fan short of a full turn are not checked") {
    const riner::Geometry parallel = riner::test::small_parallel2d();
    CHECK_FALSE(riner::fan_geometry_doubt(
        scan_of(parallel, riner::test::asymmetric_object(parallel.volume_shape))));
    riner::Geometry short_fan = with_angles(riner::test::small_fan2d(), 60, 1.5 * M_PI, false);
    CHECK_FALSE(riner::fan_geometry_doubt(
        scan_of(short_fan, riner::test::asymmetric_object(short_fan.volume_shape))));
  }
}
