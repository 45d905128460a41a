// Centre of rotation from the scan: projections of an off-centre object with a known detector
// offset, the offset forgotten, then found again, from the whole sinogram and from view pairs.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "preprocessing/centre_readings.hpp"
#include "riner/centre.hpp"
#include "riner/error.hpp"
#include "riner/phantom.hpp"
#include "riner/projector.hpp"
#include "support/asymmetric_object.hpp"
#include "support/geometries.hpp"

namespace {

riner::Scan scan_with_offset(riner::Geometry g, double offset) {
  g.offset_u = offset;
  riner::Scan s;
  s.measurement = riner::Projector(g, riner::Engine::kReference)
                      .project(riner::test::asymmetric_object(g.volume_shape));
  s.geometry = g;
  s.geometry.offset_u = 0.0;  // forgotten
  return s;
}

// Every detector element offset by its own constant (a ring's stripe), up to `share` of the
// largest reading either way: a detector of +-25% on a faint object.
riner::Scan striped(riner::Scan s, double share) {
  double top = 0.0;
  for (float v : s.measurement.data) top = std::max(top, static_cast<double>(v));
  const std::size_t views = s.geometry.n_views();
  const std::size_t per_view = s.measurement.size() / views;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> offset(-share * top, share * top);
  std::vector<float> stripes(per_view);
  for (float& o : stripes) o = static_cast<float>(offset(rng));
  for (std::size_t i = 0; i < s.measurement.size(); ++i)
    s.measurement.data[i] += stripes[i % per_view];
  return s;
}

using riner::test::with_angles;

// The scan's views in the order `from` lists them (a view may come twice), each with its angle,
// `shift` added to a view's angle the second time it comes (an encoder's reading on the way back).
riner::Scan reordered(const riner::Scan& scan, const std::vector<std::size_t>& from,
                      double shift = 0.0) {
  const std::size_t per_view = scan.measurement.size() / scan.geometry.n_views();
  riner::Scan out = scan;
  out.geometry.uniform_angles.reset();
  out.geometry.angles.clear();
  std::vector<std::size_t> shape = scan.measurement.shape;
  shape[0] = from.size();
  out.measurement = riner::Array(shape);
  std::vector<bool> seen(scan.geometry.n_views(), false);
  for (std::size_t i = 0; i < from.size(); ++i) {
    out.geometry.angles.push_back(scan.geometry.angles[from[i]] + (seen[from[i]] ? shift : 0.0));
    seen[from[i]] = true;
    std::copy_n(scan.measurement.ptr() + from[i] * per_view, per_view,
                out.measurement.ptr() + i * per_view);
  }
  return out;
}

// 0, 2, 4, ... then 1, 3, 5, ...
std::vector<std::size_t> interleaved_order(std::size_t views) {
  std::vector<std::size_t> from;
  for (std::size_t i = 0; i < views; i += 2) from.push_back(i);
  for (std::size_t i = 1; i < views; i += 2) from.push_back(i);
  return from;
}

}  // namespace

TEST_SUITE("centre") {
  TEST_CASE(
      "parallel 2D, 180 degrees with its endpoint, 360 with an even and an odd count: 0.1 px") {
    const riner::Geometry base = riner::test::small_parallel2d();
    for (const auto& [views, range, endpoint] :
         {std::tuple{61, M_PI, true}, std::tuple{90, 2.0 * M_PI, false},
          std::tuple{91, 2.0 * M_PI, false}}) {
      const riner::Geometry g = with_angles(base, static_cast<std::size_t>(views), range, endpoint);
      for (double offset : {3.4, -6.35, 0.0}) {
        const riner::CentreEstimate e = riner::estimate_centre(scan_with_offset(g, offset));
        CAPTURE(views);
        CAPTURE(offset);
        CHECK(std::fabs(e.offset_px - offset) < 0.1);
        CHECK(e.axis_column == doctest::Approx(0.5 * (g.n_u - 1.0) - e.offset_px));
        CHECK(e.method == "sinogram");
        CHECK(e.sinogram_offset_px == e.offset_px);
        // The cross-check agrees.
        CHECK(std::fabs(e.pairs_offset_px - offset) < 0.1);
        CHECK(e.pairs >= 1);
        CHECK(e.spread_px < 1.0);
      }
    }
  }

  TEST_CASE(
      "readings without structure (all equal) are refused, not matched at the search's edge") {
    const riner::Geometry g = riner::test::small_parallel2d();
    for (float value : {0.0f, 0.5f, 1e-40f}) {
      riner::Scan flat{riner::Array(g.measurement_shape(), value), g, 0};
      flat.measurement.data[3] = NAN;  // a dead reading changes nothing
      CHECK_THROWS_WITH_AS(riner::estimate_centre(flat),
                           doctest::Contains("the readings are all equal: they hold nothing to "
                                             "find the centre from"),
                           riner::InputError);
    }
  }

  TEST_CASE("an interleaved 180-degree scan (even views, then odd) reads as one in order") {
    // The views of a half-turn taken 0, 2, 4, ... then 1, 3, 5, ... steps: the sinogram found
    // no evenly spaced half-turn in file order, and the pairs none half a turn apart.
    const riner::Geometry g = with_angles(riner::test::small_parallel2d(), 60, M_PI, false);
    const riner::Scan scan = scan_with_offset(g, 3.4);
    const riner::Scan interleaved = reordered(scan, interleaved_order(g.n_views()));
    const riner::CentreEstimate in_order = riner::estimate_centre(scan);
    const riner::CentreEstimate e = riner::estimate_centre(interleaved);
    CHECK(e.method == "sinogram");
    CHECK(e.offset_px == doctest::Approx(in_order.offset_px).epsilon(1e-9));
    CHECK(std::fabs(e.offset_px - 3.4) < 0.1);
  }

  TEST_CASE(
      "a scan that turns back over its angles (0 to 180 degrees and back) reads each angle "
      "once") {
    // Each angle twice read "no evenly spaced half-turn": the second pass is left out, also
    // where the way back reads its angles a little differently.
    const riner::Geometry g = with_angles(riner::test::small_parallel2d(), 60, M_PI, false);
    const riner::Scan scan = scan_with_offset(g, 3.4);
    std::vector<std::size_t> there_and_back(g.n_views());
    std::iota(there_and_back.begin(), there_and_back.end(), std::size_t{0});
    there_and_back.insert(there_and_back.end(), there_and_back.rbegin(), there_and_back.rend());
    const riner::CentreEstimate in_order = riner::estimate_centre(scan);
    for (const double shift : {0.0, 1e-4, -1e-4}) {
      CAPTURE(shift);
      const riner::CentreEstimate e =
          riner::estimate_centre(reordered(scan, there_and_back, shift));
      CHECK(e.method == "sinogram");
      CHECK(std::fabs(e.offset_px - in_order.offset_px) < 0.01);
      CHECK(std::fabs(e.offset_px - 3.4) < 0.1);
    }
  }

  TEST_CASE("views left out as repeats: a way back over the angles, not random or few views") {
    const riner::Geometry g = with_angles(riner::test::small_parallel2d(), 60, M_PI, false);
    const riner::Scan scan = scan_with_offset(g, 3.4);
    const double step = M_PI / 60.0;
    std::vector<std::size_t> there_and_back(60);
    std::iota(there_and_back.begin(), there_and_back.end(), std::size_t{0});
    there_and_back.insert(there_and_back.end(), there_and_back.rbegin(), there_and_back.rend());
    // The way back's angles 0.15 of a step off: one view each (it was 1/8 of a step, the mean
    // step taken over both ways).
    for (const double shift : {0.0, 0.15 * step, -0.15 * step}) {
      CAPTURE(shift);
      const riner::Scan once =
          riner::preprocessing::in_angle_order(reordered(scan, there_and_back, shift));
      CHECK(once.geometry.n_views() == 60);
      CHECK(once.measurement.shape[0] == 60);
    }
    // Three times over the angles, exactly: one view each.
    std::vector<std::size_t> thrice = there_and_back;
    thrice.insert(thrice.end(), there_and_back.begin(), there_and_back.begin() + 60);
    CHECK(riner::preprocessing::in_angle_order(reordered(scan, thrice)).geometry.n_views() == 60);
    // A few clustered views (0, 1, 2 and 3 steps and 177 on): all kept (a review's; the mean
    // step's quarter, 15 steps, left out two and the pairs lost the opposite one).
    const riner::Scan few = reordered(scan, {0, 1, 2, 3, 59});
    CHECK(riner::preprocessing::in_angle_order(few).geometry.n_views() == 5);
    // Views at random angles, some close together: all kept.
    riner::Scan random = scan;
    random.geometry.uniform_angles.reset();
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> angle(0.0, M_PI);
    for (double& a : random.geometry.angles) a = angle(rng);
    CHECK(riner::preprocessing::in_angle_order(random).geometry.n_views() == 60);
  }

  TEST_CASE("an interleaved parallel 3D stack reads as one in order") {
    const riner::Geometry g = with_angles(riner::test::small_parallel3d(), 30, M_PI, false);
    const riner::Scan scan = scan_with_offset(g, -2.7);
    const riner::CentreEstimate in_order = riner::estimate_centre(scan);
    const riner::CentreEstimate e =
        riner::estimate_centre(reordered(scan, interleaved_order(g.n_views())));
    CHECK(e.offset_px == doctest::Approx(in_order.offset_px).epsilon(1e-9));
    CHECK(std::fabs(e.offset_px + 2.7) < 0.1);
    CHECK(e.rows > 1);
  }

  TEST_CASE("parallel 3D: every row shares the axis") {
    const riner::Geometry g = with_angles(riner::test::small_parallel3d(), 31, M_PI, true);
    const riner::CentreEstimate e = riner::estimate_centre(scan_with_offset(g, -2.7));
    CHECK(std::fabs(e.offset_px + 2.7) < 0.1);
    CHECK(e.rows > 1);
  }

  TEST_CASE("no view pair (180 degrees less a step): the sinogram alone") {
    const riner::Geometry open = with_angles(riner::test::small_parallel2d(), 60, M_PI, false);
    const riner::CentreEstimate e = riner::estimate_centre(scan_with_offset(open, 2.6));
    CHECK(std::fabs(e.offset_px - 2.6) < 0.1);
    CHECK(e.method == "sinogram");
    CHECK(e.pairs == 0);
    CHECK(std::isnan(e.pairs_offset_px));
    // Scans a little short of half a turn (179.5 degrees of 180 views ended 0.001 degrees
    // short of the rule's 1.5 steps and were refused).
    for (const auto& [views, degrees] : {std::pair{180, 179.5}, std::pair{100, 178.0}}) {
      CAPTURE(views);
      const riner::Geometry shorter =
          with_angles(riner::test::small_parallel2d(), static_cast<std::size_t>(views),
                      degrees * M_PI / 180.0, false);
      const riner::CentreEstimate s = riner::estimate_centre(scan_with_offset(shorter, 2.6));
      CHECK(s.method == "sinogram");
      CHECK(std::fabs(s.offset_px - 2.6) < 0.1);
    }
    // But a coarse scan missing tens of degrees is no half-turn (9 views at 15 degrees: 120).
    const riner::Geometry coarse =
        with_angles(riner::test::small_parallel2d(), 9, 9 * 15.0 * M_PI / 180.0, false);
    CHECK_THROWS_AS(riner::estimate_centre(scan_with_offset(coarse, 2.6)), riner::InputError);
  }

  TEST_CASE("a head wider than the detector, the axis 15% off its middle: the sinogram") {
    // 100 elements read a Shepp-Logan head 110 px tall, whose skull is cut at the detector's
    // ends; no view pair (90 views over 180 degrees less a step). The spectral mirror alone met
    // the padding's wrap in the columns the mirror image does not reach: -25.75 for -15, its
    // search's edge.
    riner::Geometry g = with_angles(riner::test::make_geometry(riner::GeometryType::kParallel2d, 90,
                                                               100, 1, {110, 110}, 1.0, 1.0, M_PI),
                                    90, M_PI, false);
    for (double offset : {-15.0, 13.6, 4.2}) {
      CAPTURE(offset);
      g.offset_u = offset;
      riner::Scan scan{riner::exact_projections(riner::shepp_logan(g), g), g, 0};
      scan.geometry.offset_u = 0.0;  // forgotten
      const riner::CentreEstimate e = riner::estimate_centre(scan);
      CHECK(e.method == "sinogram");
      // The cut skull biases the measure by a few tenths (0.1 px for an object within the
      // field of view).
      CHECK(std::fabs(e.offset_px - offset) < 0.5);
    }
  }

  TEST_CASE("a hot or dead column reading one value does not pull the axis onto itself") {
    // A steady column matches its own mirror image only about itself: the axis went there.
    for (const auto& [views, range] : {std::pair{60, M_PI}, std::pair{90, 2.0 * M_PI}}) {
      const riner::Geometry g =
          with_angles(riner::test::small_parallel2d(), static_cast<std::size_t>(views), range,
                      false);
      riner::Scan scan = scan_with_offset(g, 3.4);
      double top = 0.0;
      for (float v : scan.measurement.data) top = std::max(top, static_cast<double>(v));
      for (std::size_t v = 0; v < g.n_views(); ++v) {
        scan.measurement.data[v * g.n_u + 20] = static_cast<float>(5.0 * top);  // hot
        scan.measurement.data[v * g.n_u + 70] = 0.0f;                          // dead
      }
      CAPTURE(views);
      const riner::CentreEstimate e = riner::estimate_centre(scan);
      CHECK(std::fabs(e.offset_px - 3.4) < 0.15);
      if (e.pairs > 1) CHECK(std::fabs(e.pairs_offset_px - 3.4) < 0.15);
    }
  }

  TEST_CASE("one noisy, dim view (a detector's hiccup) barely moves the sinogram's answer") {
    const riner::Geometry g = with_angles(riner::test::small_parallel2d(), 61, M_PI, true);
    riner::Scan scan = scan_with_offset(g, 3.4);
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, 1.0);
    double top = 0.0;
    for (float v : scan.measurement.data) top = std::max(top, static_cast<double>(v));
    const std::size_t n = g.n_u;
    for (std::size_t v = 0; v < g.n_views(); ++v) {
      // 0.5% noise on every view; the endpoint view (the only one with a pair, view 0) has
      // 25 times that and reads 5% low.
      const double sigma = (v + 1 == g.n_views() ? 0.125 : 0.005) * top;
      const double drop = v + 1 == g.n_views() ? 0.05 * top : 0.0;
      for (std::size_t e = 0; e < n; ++e) {
        scan.measurement.data[v * n + e] += static_cast<float>(sigma * noise(rng) - drop);
      }
    }
    const riner::CentreEstimate e = riner::estimate_centre(scan);
    CHECK(e.method == "sinogram");
    CHECK(std::fabs(e.offset_px - 3.4) < 0.15);
  }

  TEST_CASE("a half acquisition (a full turn, the axis near one end): found within 0.5 px") {
    // 60 elements, the axis 12 columns from either end: a view and its opposite share 25
    // columns; the object reaches past the nearer end.
    riner::Geometry g = with_angles(riner::test::make_geometry(riner::GeometryType::kParallel2d,
                                                               120, 60, 1, {61, 67}, 1.0, 1.0,
                                                               2.0 * M_PI),
                                    120, 2.0 * M_PI, false);
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 1.0);
    for (double offset : {17.5, -16.7}) {
      CAPTURE(offset);
      riner::Scan scan = scan_with_offset(g, offset);
      double top = 0.0;
      for (float v : scan.measurement.data) top = std::max(top, static_cast<double>(v));
      for (float& v : scan.measurement.data) v += static_cast<float>(0.005 * top * noise(rng));
      const riner::CentreEstimate e = riner::estimate_centre(scan);
      CHECK(e.half_acquisition);
      CHECK(e.method == "view pairs, half acquisition");
      CHECK(std::fabs(e.offset_px - offset) < 0.5);
      CHECK(e.spread_px < 1.0);
      CHECK(std::isnan(e.sinogram_offset_px));
    }
    // The same detector centred: the central answer stands.
    const riner::CentreEstimate centred = riner::estimate_centre(scan_with_offset(g, 1.3));
    CHECK_FALSE(centred.half_acquisition);
    CHECK(centred.method == "sinogram");
    CHECK(std::fabs(centred.offset_px - 1.3) < 0.1);
    CHECK(riner::centre_search_covers([&] {
      riner::Geometry far = g;
      far.offset_u = 17.5;
      return far;
    }()));
  }

  TEST_CASE(
      "neither a half-turn nor a view pair, or a divergent beam: InputError saying what to do") {
    const riner::Geometry short_scan =
        with_angles(riner::test::small_parallel2d(), 40, 0.7 * M_PI, true);
    CHECK_THROWS_WITH_AS(riner::estimate_centre(scan_with_offset(short_scan, 1.0)),
                         doctest::Contains("no two are half a turn apart"), riner::InputError);
    riner::Scan fan;
    fan.geometry = with_angles(riner::test::small_fan2d(), 40, 1.2 * M_PI, true);
    fan.measurement = riner::Array(fan.geometry.measurement_shape());
    CHECK_THROWS_WITH_AS(riner::estimate_centre(fan),
                         doctest::Contains("views that step evenly over a full turn"),
                         riner::InputError);
    riner::Scan cone;
    cone.geometry = with_angles(riner::test::small_cone3d(), 30, M_PI, true);
    cone.measurement = riner::Array(cone.geometry.measurement_shape());
    CHECK_THROWS_WITH_AS(riner::estimate_centre(cone),
                         doctest::Contains("views that step evenly over a full turn"),
                         riner::InputError);
  }

  TEST_CASE("a fan beam over a full turn: the offset from conjugate rays") {
    for (const double offset : {2.7, -4.2, 0.0}) {
      const riner::CentreEstimate e =
          riner::estimate_centre(scan_with_offset(riner::test::small_fan2d(), offset));
      CAPTURE(offset);
      CHECK(e.method == "conjugate rays");
      CHECK(std::fabs(e.offset_px - offset) < 0.15);
      CHECK(e.axis_column == doctest::Approx(48.0 - e.offset_px));
      CHECK(e.pairs > 1000);
    }
    // The turn's end view as well (91 views, the last at 360 degrees).
    const riner::Geometry closed = with_angles(riner::test::small_fan2d(), 91, 2.0 * M_PI, true);
    CHECK(std::fabs(riner::estimate_centre(scan_with_offset(closed, 1.6)).offset_px - 1.6) < 0.15);
    // The views in shuffled order, each with its angle (an interleaved acquisition): the same.
    const riner::Scan ordered = scan_with_offset(riner::test::small_fan2d(), 2.7);
    const std::size_t views = ordered.geometry.n_views();
    REQUIRE(std::gcd(views, std::size_t{7}) == 1);
    std::vector<std::size_t> from;
    for (std::size_t i = 0; i < views; ++i) from.push_back((i * 7) % views);  // 7: prime to it
    const riner::Scan shuffled = reordered(ordered, from);
    CHECK(riner::estimate_centre(shuffled).offset_px ==
          doctest::Approx(riner::estimate_centre(ordered).offset_px).epsilon(1e-9));
  }

  TEST_CASE("rings do not move the axis: stripes over a full turn, a 180-degree sinogram") {
    // A conjugate reading lies on another element: two elements' offsets apart at every
    // candidate axis. On ringed scans of a faint object (an audit's: responses +-25%, line
    // integrals up to 1.5) a fan's axis went 1.7 px off, a cone's 1.9, a parallel half
    // acquisition's to the wrong side (+27.8 for -45). Each element's full-turn mean is taken
    // out first (an element and its conjugate see the same lines over a full turn).
    for (const double offset : {2.7, -4.2}) {
      CAPTURE(offset);
      const riner::CentreEstimate fan = riner::estimate_centre(
          striped(scan_with_offset(riner::test::small_fan2d(), offset), 0.3));
      CHECK(std::fabs(fan.offset_px - offset) < 0.15);
      const riner::Geometry cone = with_angles(riner::test::small_cone3d(), 120, 2.0 * M_PI, false);
      const riner::CentreEstimate c =
          riner::estimate_centre(striped(scan_with_offset(cone, offset), 0.3));
      CHECK(std::fabs(c.offset_px - offset) < 0.2);
    }
    const riner::Geometry half =
        riner::test::make_geometry(riner::GeometryType::kFan2d, 180, 64, 1, {64, 64}, 1.5, 1.0);
    const riner::CentreEstimate h =
        riner::estimate_centre(striped(scan_with_offset(half, 19.5), 0.3));
    CHECK(h.half_acquisition);
    CHECK(std::fabs(h.offset_px - 19.5) < 0.5);
    const riner::Geometry turn =
        with_angles(riner::test::small_parallel2d(), 120, 2.0 * M_PI, false);
    CHECK(std::fabs(riner::estimate_centre(striped(scan_with_offset(turn, -3.3), 0.3)).offset_px +
                    3.3) < 0.1);
    // Over half a turn an element's mean is not its mirror's (a half-turn sees the object from
    // one side): the column means are taken out only where the stripes outweigh the object's
    // change over the views, and either way the stripes and the object's one-sided half-turn
    // mean are alike in part (3.00 px with the means taken out, 3.02 without).
    const riner::Geometry open = with_angles(riner::test::small_parallel2d(), 60, M_PI, false);
    CHECK(std::fabs(riner::estimate_centre(striped(scan_with_offset(open, 2.6), 0.3)).offset_px -
                    2.6) < 0.5);
  }

  TEST_CASE("a fan beam's search reaches the detector's central half: 40 px off on 240") {
    // The search spanned 32 px about the geometry's offset and took its end for an answer
    // (an audit's: 34.50 for 40 on 240 elements).
    const riner::Geometry g =
        riner::test::make_geometry(riner::GeometryType::kFan2d, 90, 240, 1, {64, 64}, 1.0, 1.0);
    for (const double offset : {40.0, -37.5}) {
      CAPTURE(offset);
      const riner::CentreEstimate e = riner::estimate_centre(scan_with_offset(g, offset));
      CHECK_FALSE(e.half_acquisition);
      CHECK(std::fabs(e.offset_px - offset) < 0.15);
    }
  }

  TEST_CASE("a fan beam's half acquisition: the axis near one end from conjugate rays") {
    // 64 elements, the axis 12 from either end; only the rays around it have conjugates on
    // the detector.
    const riner::Geometry g =
        riner::test::make_geometry(riner::GeometryType::kFan2d, 180, 64, 1, {64, 64}, 1.5, 1.0);
    for (const double offset : {19.5, -18.3}) {
      CAPTURE(offset);
      const riner::CentreEstimate e = riner::estimate_centre(scan_with_offset(g, offset));
      CHECK(e.half_acquisition);
      CHECK(e.method == "conjugate rays, half acquisition");
      CHECK(std::fabs(e.offset_px - offset) < 0.5);
      // The geometry already telling the half acquisition, exactly or a few pixels off: the
      // search around it compares the few conjugates relatively too (it was pulled inwards).
      for (const double told : {offset, offset - 3.0, offset + 2.5}) {
        CAPTURE(told);
        riner::Scan scan = scan_with_offset(g, offset);
        scan.geometry.offset_u = told;
        const riner::CentreEstimate again = riner::estimate_centre(scan);
        CHECK(again.half_acquisition);
        CHECK(std::fabs(again.offset_px - offset) < 0.5);
      }
    }
    const riner::CentreEstimate centred = riner::estimate_centre(scan_with_offset(g, 2.2));
    CHECK_FALSE(centred.half_acquisition);
    CHECK(std::fabs(centred.offset_px - 2.2) < 0.15);
    // A half acquisition declared (20 px) whose search reaches the central half and finds the
    // axis there: no half acquisition (it said one).
    for (const double axis : {0.0, 6.0, -12.0}) {
      CAPTURE(axis);
      riner::Scan told = scan_with_offset(g, axis);
      told.geometry.offset_u = 20.0;
      const riner::CentreEstimate middle = riner::estimate_centre(told);
      CHECK(std::fabs(middle.offset_px - axis) < 0.15);
      CHECK_FALSE(middle.half_acquisition);
      CHECK(middle.method == "conjugate rays");
    }
  }

  TEST_CASE("a fan whose geometry's offset is far from its axis: the axis found all the same") {
    // The search went about the geometry's offset and its mirror image only, by the absolute
    // cost: on 500 elements 20 px given as 150 (a half acquisition declared) read -176.00 px,
    // 150 given as 200 read -233.30, 20 given as -120 -181.53, 120 given as 0 -124.71; on 2000,
    // 400 given as 0 read 7.50.
    const riner::Geometry g =
        riner::test::make_geometry(riner::GeometryType::kFan2d, 180, 241, 1, {96, 96}, 1.5, 1.0);
    for (const auto& [offset, told] :
         {std::pair{8.3, 75.0}, std::pair{8.3, -95.0}, std::pair{-21.6, 45.0},
          std::pair{-21.6, -80.0}, std::pair{84.4, 104.0}, std::pair{84.4, 140.0},
          std::pair{-92.7, 45.0}, std::pair{-92.7, -70.0}, std::pair{8.3, -50.0},
          std::pair{-21.6, 50.0}, std::pair{45.2, 0.0}, std::pair{-52.6, 0.0},
          std::pair{55.1, 55.1}, std::pair{-57.3, 40.0}}) {
      CAPTURE(offset);
      CAPTURE(told);
      riner::Scan scan = scan_with_offset(g, offset);
      scan.geometry.offset_u = told;
      const riner::CentreEstimate e = riner::estimate_centre(scan);
      CHECK(e.half_acquisition == (std::fabs(offset) > 60.0));
      CHECK(std::fabs(e.offset_px - offset) < 0.5);
    }
  }

  TEST_CASE("a cone beam over a full turn: the offset from the fan through the source's plane") {
    const riner::Geometry cone = with_angles(riner::test::small_cone3d(), 120, 2.0 * M_PI, false);
    for (const double offset : {2.2, -3.4}) {
      const riner::CentreEstimate e = riner::estimate_centre(scan_with_offset(cone, offset));
      CAPTURE(offset);
      CHECK(e.method == "conjugate rays");
      CHECK(std::fabs(e.offset_px - offset) < 0.2);
    }
    // The rows about the source's plane unread (NaN): said so, not "views that step evenly".
    riner::Scan blind = scan_with_offset(cone, 2.2);
    const std::size_t rows = cone.n_v;
    const std::size_t n_u = cone.n_u;
    for (std::size_t i = 0; i < blind.measurement.size(); ++i) {
      const std::size_t row = i / n_u % rows;
      if (row + 2 >= rows / 2 && row <= rows / 2 + 1) blind.measurement.data[i] = NAN;
    }
    CHECK_THROWS_WITH_AS(riner::estimate_centre(blind),
                         doctest::Contains("the detector rows through the source's plane, where "
                                           "conjugate rays meet, read no two different finite"),
                         riner::InputError);
  }
}
