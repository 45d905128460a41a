// Which +inf readings training keeps as bounds (a beam the object stopped) and which it leaves
// unread (a dead element): model/starved_readings.hpp.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

#include "model/starved_readings.hpp"
#include "riner/rays.hpp"
#include "support/geometries.hpp"

namespace {

// 6 views of 12 elements reading 1 (air at 0 at the ends), a metal band at elements 5-6 in
// views 0-3 whose edges (4 and 7) read near the largest reading, 16.
riner::Array metal_scan() {
  riner::Array a({6, 12});
  for (std::size_t v = 0; v < 6; ++v) {
    for (std::size_t e = 0; e < 12; ++e) {
      a(v, e) = (e < 2 || e > 9) ? 0.0f : 1.0f;
    }
    if (v > 3) continue;
    a(v, 4) = 15.0f;
    a(v, 5) = INFINITY;
    a(v, 6) = INFINITY;
    a(v, 7) = v == 0 ? 16.0f : 14.0f;
  }
  return a;
}

// 48 views of 20 elements reading 1, a metal band (+inf, 4 wide, edges at 15-16) moving one
// element every 6 views; elements 2-5 go dark together from view 20 on (a module failing).
riner::Array failing_module_scan() {
  riner::Array a({48, 20}, 1.0f);
  for (std::size_t v = 0; v < 48; ++v) {
    const std::size_t m = 8 + v / 6;
    a(v, m - 1) = 15.0f;
    for (std::size_t e = m; e < m + 4; ++e) a(v, e) = INFINITY;
    a(v, m + 4) = 16.0f;
    if (v >= 20) {
      for (std::size_t e = 2; e < 6; ++e) a(v, e) = INFINITY;
    }
  }
  return a;
}

// 24 views of 16 elements reading 1, the axis at 7.5; a metal pin on it stops elements 6-9 in
// every view, and its edges (5, 10) read near the largest, 15-16, or nothing (every third view).
riner::Array pin_on_axis_scan() {
  riner::Array a({24, 16}, 1.0f);
  for (std::size_t v = 0; v < 24; ++v) {
    for (std::size_t e = 6; e < 10; ++e) a(v, e) = INFINITY;
    a(v, 5) = v % 3 == 0 ? INFINITY : 15.0f;
    a(v, 10) = v % 3 == 1 ? INFINITY : 16.0f;
  }
  return a;
}

}  // namespace

TEST_SUITE("starved_readings") {
  TEST_CASE(
      "elements dark in every view, centred on the axis, their edges dense or dark: metal "
      "on the axis, bounds") {
    // They were dead: a 3/mm pin on the axis of a simulated fan scan read 0.62 (now 2.23).
    riner::Array a = pin_on_axis_scan();
    const riner::model::StarvedReadings s = riner::model::mark_starved_readings(a, 24, 7.5);
    CHECK(s.floor == 16.0f);
    for (std::size_t v = 0; v < 24; ++v) {
      for (std::size_t e = 6; e < 10; ++e) CHECK(riner::model::is_starved(a(v, e)));
    }
    CHECK(s.count == 24 * 4 + 8 + 8);  // the edges' dark readings join the run: wide
    // A spike above the largest (19, below the corrupt limit), or an element of the run unread
    // (NaN) throughout: metal still (a review's: 611 bounds fell to 161).
    riner::Array spiked = pin_on_axis_scan();
    spiked(2, 0) = 19.0f;
    riner::model::mark_starved_readings(spiked, 24, 7.5);
    CHECK(riner::model::is_starved(spiked(1, 7)));
    riner::Array masked = pin_on_axis_scan();
    for (std::size_t v = 0; v < 24; ++v) masked(v, 7) = NAN;
    riner::model::mark_starved_readings(masked, 24, 7.5);
    CHECK(riner::model::is_starved(masked(1, 6)));
    CHECK(riner::model::is_starved(masked(1, 8)));
    CHECK(std::isnan(masked(1, 7)));
    // The axis a pixel and a half off the run's centre, or unknown: dead, as before.
    for (const double axis : {6.0, 9.0, std::numeric_limits<double>::quiet_NaN()}) {
      CAPTURE(axis);
      riner::Array b = pin_on_axis_scan();
      riner::model::mark_starved_readings(b, 24, axis);
      for (std::size_t v = 0; v < 24; ++v) {
        for (std::size_t e = 6; e < 10; ++e) CHECK(std::isnan(b(v, e)));
      }
    }
  }

  TEST_CASE(
      "on the axis, a lone dead element, a dead module in a thick body or beside a blank "
      "frame: dead") {
    // A lone dead element among dense rays (a bound would draw a dense dot on the axis).
    riner::Array lone = pin_on_axis_scan();
    for (std::size_t v = 0; v < 24; ++v) lone(v, 6) = lone(v, 9) = 15.0f;
    riner::Array narrow = lone;
    riner::model::mark_starved_readings(narrow, 24, 7.5);
    for (std::size_t v = 0; v < 24; ++v) CHECK(std::isnan(narrow(v, 7)));
    // Four dead elements on the axis of a thick body: the rays beside them read near the
    // largest, and nothing now and then (photon-starved), but no more than those beyond (a
    // review's disc of 0.14/mm at 10^4 photons: bounds at the largest made its middle 0.46).
    riner::Array thick = pin_on_axis_scan();
    for (std::size_t v = 0; v < 24; ++v) {
      for (std::size_t e = 1; e < 15; ++e) {
        if (e < 6 || e > 9) thick(v, e) = 14.0f + 0.1f * static_cast<float>((v + e) % 5);
      }
      if (v % 7 == 0) thick(v, 5) = thick(v, 10) = INFINITY;
    }
    thick(0, 0) = 16.0f;
    riner::model::mark_starved_readings(thick, 24, 7.5);
    for (std::size_t v = 0; v < 24; ++v) {
      for (std::size_t e = 6; e < 10; ++e) CHECK(std::isnan(thick(v, e)));
    }
    // A bone rod on the axis under a dead module: its edges step above what lies beyond them,
    // but read far below the scan's largest (a plate's edge-on rays in one view), where the
    // bounds would go: dead (a review's: 1.36/mm for 0.18).
    riner::Array rod({24, 16}, 1.7f);
    for (std::size_t v = 0; v < 24; ++v) {
      for (std::size_t e = 6; e < 10; ++e) rod(v, e) = INFINITY;
      rod(v, 5) = rod(v, 10) = 2.8f;
    }
    rod(3, 2) = 7.14f;
    riner::model::mark_starved_readings(rod, 24, 7.5);
    for (std::size_t v = 0; v < 24; ++v) CHECK(std::isnan(rod(v, 7)));
    // Beside elements dying part-way (dark from views 4 and 6 to the end), which read as the
    // body before: dead (a review's: the module's middle 3.67/mm for 0.05).
    riner::Array dying = pin_on_axis_scan();
    for (std::size_t v = 0; v < 24; ++v) {
      dying(v, 5) = v >= 4 ? INFINITY : 1.0f;
      dying(v, 10) = v >= 6 ? INFINITY : 1.0f;
    }
    dying(0, 0) = 16.0f;
    riner::model::mark_starved_readings(dying, 24, 7.5);
    for (std::size_t v = 0; v < 24; ++v) CHECK(std::isnan(dying(v, 7)));
    // A module in a body whose rays beside it read as those beyond, and a blank frame (a lost
    // view): dead (a first version counted the frame as the edges' darkness, and took the
    // module for metal).
    riner::Array blank({24, 16}, 1.0f);
    for (std::size_t v = 0; v < 24; ++v) {
      for (std::size_t e = 6; e < 10; ++e) blank(v, e) = INFINITY;
    }
    for (std::size_t e = 0; e < 16; ++e) blank(3, e) = INFINITY;
    blank(0, 0) = 16.0f;
    riner::model::mark_starved_readings(blank, 24, 7.5);
    CHECK(std::isnan(blank(1, 7)));
    // Edges dense in fewer than three quarters of the views: dead.
    riner::Array sparse = pin_on_axis_scan();
    for (std::size_t v = 0; v < 24; v += 2) sparse(v, 5) = 2.0f;
    riner::model::mark_starved_readings(sparse, 24, 7.5);
    CHECK(std::isnan(sparse(1, 7)));
  }

  TEST_CASE("+inf beside rays near the largest reading is a bound at it") {
    riner::Array a = metal_scan();
    const riner::model::StarvedReadings s = riner::model::mark_starved_readings(a, 6);
    CHECK(s.count == 8);
    CHECK(s.floor == 15.0f);  // the views' largest readings: 16, 15, 15, 15, 1, 1
    for (std::size_t v = 0; v < 4; ++v) {
      CHECK(riner::model::is_starved(a(v, 5)));
      CHECK(riner::model::is_starved(a(v, 6)));
    }
  }

  TEST_CASE("+inf among rays well below the largest is a dead element: NaN") {
    riner::Array a = metal_scan();
    a(2, 1) = INFINITY;  // in air
    a(4, 8) = INFINITY;  // in the object (reads 1 around), far below 16
    a(4, 9) = NAN;       // a NaN beside it is skipped: the run's neighbours are 1 and 0
    const riner::model::StarvedReadings s = riner::model::mark_starved_readings(a, 6);
    CHECK(s.count == 8);
    CHECK(std::isnan(a(2, 1)));
    CHECK(std::isnan(a(4, 8)));
  }

  TEST_CASE("a run wider than two elements is a stopped beam whatever its neighbours read") {
    riner::Array a = metal_scan();
    a(4, 3) = a(4, 4) = a(4, 5) = INFINITY;  // 3 wide, among readings of 1
    a(5, 3) = a(5, 4) = INFINITY;            // 2 wide: dead elements' width
    const riner::model::StarvedReadings s = riner::model::mark_starved_readings(a, 6);
    CHECK(s.count == 11);
    CHECK(riner::model::is_starved(a(4, 4)));
    CHECK(std::isnan(a(5, 3)));
    CHECK(std::isnan(a(5, 4)));
  }

  TEST_CASE("an element dark for views / 12 views in a row among dense rays is dying, not metal") {
    // 48 views; elements 4-7 read 15 (near the largest, 16: a body's thickest rays). Element 5
    // goes dark from view 20 on (28 views, past max(24, 48 / 12)); element 6 for 3 views only.
    riner::Array a({48, 12}, 1.0f);
    for (std::size_t v = 0; v < 48; ++v) {
      for (std::size_t e = 4; e < 8; ++e) a(v, e) = 15.0f;
      a(v, 9) = 16.0f;
      if (v >= 20) a(v, 5) = INFINITY;
      if (v >= 30 && v < 33) a(v, 6) = INFINITY;
    }
    const riner::model::StarvedReadings s = riner::model::mark_starved_readings(a, 48);
    CHECK(s.count == 3);
    CHECK(std::isnan(a(25, 5)));
    CHECK(std::isnan(a(31, 5)));  // the run 5-6 in view 31 is 2 wide: each element on its own
    CHECK(riner::model::is_starved(a(31, 6)));
  }

  TEST_CASE("a thin trace that follows a point's projection is a stopped beam, whatever beside") {
    // A fan beam's 90 views of 97 elements reading 1, element 90 reading 16 (the largest, a
    // dense edge); a wire at (12, 5) mm (and another, below) darkens the two elements about its
    // projection in every view, its neighbours, partly covered, reading 3, far below 0.75 of 16:
    // before, all 180 of its readings were dead elements'. Not a trace: element 2 dead throughout,
    // a glitch of elements 80-81 in views 8-10, element 85 dying from view 60 on, and a dead
    // element that drifts from 10 to 14 across the scan (projections shifted to correct a drift),
    // which moves and joins from view to view as a trace does but follows no point (a review's:
    // read as one, a pin scene's error 0.01 -> 0.39 /mm).
    const riner::Geometry g = riner::test::small_fan2d();
    const std::size_t views = g.n_views(), n = g.n_u;
    riner::Array a({views, n}, 1.0f);
    const auto wire_at = [&](std::size_t v, double x, double y) {
      const double u = riner::project_to_detector(g, v, riner::Vec3{x, y, 0.0}).u;
      return static_cast<std::size_t>(std::lround(u - 0.5));
    };
    // A second wire, at (-10, -8): its trace crosses the first's (two such paths meet once in
    // half a turn) and the two join into one component, told apart point by point.
    std::vector<char> wires(views * n, 0);
    for (std::size_t v = 0; v < views; ++v) {
      for (const auto& [x, y] : {std::pair{12.0, 5.0}, std::pair{-10.0, -8.0}}) {
        const std::size_t m = wire_at(v, x, y);
        for (std::size_t e : {m - 1, m + 2}) {
          if (!wires[v * n + e]) a(v, e) = 3.0f;
        }
        a(v, m) = a(v, m + 1) = INFINITY;
        wires[v * n + m] = wires[v * n + m + 1] = 1;
      }
      a(v, 90) = 16.0f;
      a(v, 2) = INFINITY;
      if (v >= 8 && v < 11) a(v, 80) = a(v, 81) = INFINITY;
      if (v >= 60) a(v, 85) = INFINITY;
      a(v, 10 + v / 18) = INFINITY;
    }
    CHECK(n > 90);
    riner::Array without_geometry = a;
    const riner::model::StarvedReadings s =
        riner::model::mark_starved_readings(a, views, riner::model::axis_column(g), &g);
    CHECK(s.count == static_cast<std::size_t>(std::count(wires.begin(), wires.end(), 1)));
    CHECK(riner::model::is_starved(a(0, wire_at(0, 12.0, 5.0))));
    CHECK(riner::model::is_starved(a(77, wire_at(77, 12.0, 5.0) + 1)));
    CHECK(riner::model::is_starved(a(30, wire_at(30, -10.0, -8.0))));
    CHECK(std::isnan(a(0, 2)));
    CHECK(std::isnan(a(9, 80)));
    CHECK(std::isnan(a(70, 85)));
    CHECK(std::isnan(a(45, 10 + 45 / 18)));
    // Without the geometry no run is read as a trace: only where the two traces merge into runs
    // wider than two elements are they bounds.
    const std::size_t merged = riner::model::mark_starved_readings(without_geometry, views).count;
    CHECK(merged > 0);
    CHECK(merged < 20);
  }

  TEST_CASE("a wire's trace cut by a dead element is kept, each part on the whole path") {
    // The fan beam above, one wire, and element 48 (the axis column) dead throughout: the trace
    // falls in parts, each spanning fewer views and sweeping less than the whole (a part of a
    // real scan's swept 9.9 elements over its own views and was refused as a point near the
    // axis; the sweep is the point's over the scan).
    const riner::Geometry g = riner::test::small_fan2d();
    const std::size_t views = g.n_views(), n = g.n_u;
    riner::Array a({views, n}, 1.0f);
    std::size_t wire = 0;
    for (std::size_t v = 0; v < views; ++v) {
      const double u = riner::project_to_detector(g, v, riner::Vec3{12.0, 5.0, 0.0}).u;
      const auto m = static_cast<std::size_t>(std::lround(u - 0.5));
      a(v, m - 1) = a(v, m + 2) = 3.0f;
      a(v, m) = a(v, m + 1) = INFINITY;
      wire += (m != 48) + (m + 1 != 48);
      a(v, 90) = 16.0f;
      a(v, 48) = INFINITY;
    }
    const riner::model::StarvedReadings s =
        riner::model::mark_starved_readings(a, views, riner::model::axis_column(g), &g);
    // A part spanning under a quarter of the views stays unread (here 31 of 176 readings).
    CHECK(s.count > 8 * wire / 10);
    CHECK(s.count <= wire);
    for (std::size_t v = 0; v < views; ++v) CHECK(std::isnan(a(v, 48)));
  }

  TEST_CASE("a dead element drifting a few pixels about the axis is no trace") {
    // A point within a few pixels of the axis sweeps as little: a dead element shifted 4 px
    // across the axis column over the scan (registration, a runout corrected) follows one as
    // closely as a wire would (a review's: kept, a fake dot of 6-9 /mm at the centre).
    const riner::Geometry g = riner::test::small_parallel2d();
    const std::size_t views = g.n_views(), n = g.n_u;
    const double axis = riner::model::axis_column(g);
    riner::Array a({views, n}, 1.0f);
    for (std::size_t v = 0; v < views; ++v) {
      a(v, 90) = 16.0f;
      const double drift = -2.0 + 4.0 * static_cast<double>(v) / static_cast<double>(views - 1);
      a(v, static_cast<std::size_t>(std::lround(axis + drift))) = INFINITY;
    }
    CHECK(riner::model::mark_starved_readings(a, views, axis, &g).count == 0);
  }

  TEST_CASE("a module failing part-way, a blank frame: unread, not metal") {
    // failing_module_scan's module; view 10 reads nothing at all (a blank frame).
    riner::Array a = failing_module_scan();
    for (std::size_t e = 0; e < 20; ++e) a(10, e) = INFINITY;
    const riner::model::StarvedReadings s = riner::model::mark_starved_readings(a, 48);
    CHECK(s.count == 47 * 4);  // the band in every view but the blank one
    CHECK(riner::model::is_starved(a(40, 8 + 40 / 6)));
    for (std::size_t e = 2; e < 6; ++e) CHECK(std::isnan(a(40, e)));
    for (std::size_t e = 0; e < 20; ++e) CHECK(std::isnan(a(10, e)));
  }

  TEST_CASE("an element dark since before the module failed is of the module: unread") {
    // The module above, and element 6 beside it dark from view 14 on, before the module (as the
    // metal's trace darkens an element just before a module fails): its run of its own was kept
    // as bounds, wide with the module's elements, and the field took them as streaks.
    riner::Array a = failing_module_scan();
    for (std::size_t v = 14; v < 48; ++v) a(v, 6) = INFINITY;
    const riner::model::StarvedReadings s = riner::model::mark_starved_readings(a, 48);
    CHECK(s.count == 48 * 4);
    for (std::size_t v = 14; v < 48; ++v) CHECK(std::isnan(a(v, 6)));
  }

  TEST_CASE("an element that reads nothing in any view is dead, whatever its neighbours read") {
    riner::Array a = metal_scan();
    for (std::size_t v = 0; v < 6; ++v) a(v, 6) = INFINITY, a(v, 5) = 15.5f;
    const riner::model::StarvedReadings s = riner::model::mark_starved_readings(a, 6);
    CHECK(s.count == 0);
    CHECK(s.floor == 0.0f);  // no bound kept
    for (std::size_t v = 0; v < 6; ++v) CHECK(std::isnan(a(v, 6)));
  }

  TEST_CASE("one bad reading under the corrupt limit does not set the floor") {
    // A review's: one reading of 100 in a view (under the corrupt limit behind metal) was the
    // floor of every bound: a 3/mm disc read 23.6, FBP's 11.4. (The rules still weigh edges
    // against the scan's largest, which a plate edge-on in one view sets for real: here the
    // spike leaves the pin's edges short of it, and its elements, dark in every view, are
    // taken for dead; only its edges' dark readings are kept.)
    riner::Array a = pin_on_axis_scan();
    riner::Array spiked = a;
    spiked(5, 1) = 100.0f;
    const riner::model::StarvedReadings plain = riner::model::mark_starved_readings(a, 24, 7.5);
    const riner::model::StarvedReadings s = riner::model::mark_starved_readings(spiked, 24, 7.5);
    CHECK(plain.floor == 16.0f);
    CHECK(s.floor == 16.0f);
    CHECK(plain.count == 112);
    CHECK(s.count == 16);
  }

  TEST_CASE("corrupt spikes do not set the floor; a scan of nothing finite keeps no bound") {
    riner::Array a = metal_scan();
    a(1, 9) = 1e5f;  // beyond largest_reading: left out of the largest
    riner::model::StarvedReadings s = riner::model::mark_starved_readings(a, 6);
    CHECK(s.floor == 15.0f);
    CHECK(s.count == 8);
    riner::Array none({2, 3}, std::vector<float>(6, INFINITY));
    s = riner::model::mark_starved_readings(none, 2);
    CHECK(s.count == 0);
    for (float x : none.data) CHECK(std::isnan(x));
  }

  TEST_CASE("3D: runs are looked for along each detector row") {
    riner::Array a({2, 2, 4}, std::vector<float>{1, 9, INFINITY, 1,   // view 0, row 0: bound
                                                 1, INFINITY, 1, 1,   // row 1: dead
                                                 1, INFINITY, 10, 1,  // view 1, row 0: bound
                                                 1, 1, 1, 1});
    const riner::model::StarvedReadings s = riner::model::mark_starved_readings(a, 2);
    CHECK(s.count == 2);
    CHECK(s.floor == 9.0f);  // of two views' largest, 9 and 10, the lower
    CHECK(riner::model::is_starved(a.data[2]));
    CHECK(std::isnan(a.data[5]));
    CHECK(riner::model::is_starved(a.data[9]));
  }
}
