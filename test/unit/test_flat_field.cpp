// Raw projections to the measurement: -ln((I - D) / (F - D)), frames averaged, invalid
// readings +inf (no light) or NaN and counted.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "riner/error.hpp"
#include "riner/flat_field.hpp"
#include "support/geometries.hpp"

namespace {

using riner::Array;
using riner::FlatFieldReport;

}  // namespace

TEST_SUITE("flat_field") {
  TEST_CASE("recovers rho from I = D + (F - D) exp(-rho), frames averaged") {
    // 3 views of a 2 x 3 detector; 2 flat frames, 3 dark frames, per-pixel fields.
    const std::size_t views = 3;
    const std::size_t pixels = 6;
    Array flats({2, 2, 3});
    Array darks({3, 2, 3});
    for (std::size_t p = 0; p < pixels; ++p) {
      flats.data[p] = 1000.0f + 10.0f * p;  // the two frames average to 1000 + 10p + 5
      flats.data[pixels + p] = 1010.0f + 10.0f * p;
      for (std::size_t f = 0; f < 3; ++f) darks.data[f * pixels + p] = 90.0f + 10.0f * f + p;
    }
    Array rho_true({views, 2, 3});
    Array raw({views, 2, 3});
    for (std::size_t v = 0; v < views; ++v) {
      for (std::size_t p = 0; p < pixels; ++p) {
        const double rho = 0.1 * static_cast<double>(v + 1) + 0.05 * static_cast<double>(p);
        const double flat = 1005.0 + 10.0 * p;
        const double dark = 100.0 + p;
        rho_true.data[v * pixels + p] = static_cast<float>(rho);
        raw.data[v * pixels + p] = static_cast<float>(dark + (flat - dark) * std::exp(-rho));
      }
    }
    FlatFieldReport report;
    const Array rho = riner::flat_field_normalise(raw, flats, darks, &report);
    REQUIRE(rho.shape == raw.shape);
    for (std::size_t i = 0; i < rho.size(); ++i) {
      CHECK(rho.data[i] == doctest::Approx(rho_true.data[i]).epsilon(1e-5));
    }
    CHECK(report.flat_frames == 2);
    CHECK(report.dark_frames == 3);
    CHECK(report.invalid_readings == 0);
    CHECK(report.pixels_without_beam == 0);
  }

  TEST_CASE("2D projections, one flat frame, no dark: D = 0") {
    const Array raw({2, 3}, {50.0f, 100.0f, 25.0f, 100.0f, 100.0f, 100.0f});
    const Array flat({3}, {100.0f, 100.0f, 100.0f});
    FlatFieldReport report;
    const Array rho = riner::flat_field_normalise(raw, flat, Array(), &report);
    CHECK(rho.data[0] == doctest::Approx(std::log(2.0)));
    CHECK(rho.data[1] == doctest::Approx(0.0));
    CHECK(rho.data[2] == doctest::Approx(std::log(4.0)));
    CHECK(report.flat_frames == 1);
    CHECK(report.dark_frames == 0);
  }

  TEST_CASE("readings at or below the dark read +inf, pixels without beam NaN, counted") {
    // Pixel 0: flat equals dark (no beam): both of its readings NaN. Pixel 1: one reading
    // below the dark (no light: -ln 0 = +inf), one NaN. Pixel 2: valid, reading above the flat (rho
    // < 0 is kept).
    const Array raw({2, 3}, {50.0f, 5.0f, 150.0f, 60.0f, NAN, 80.0f});
    const Array flat({3}, {10.0f, 100.0f, 110.0f});
    const Array dark({3}, {10.0f, 10.0f, 10.0f});
    FlatFieldReport report;
    const Array rho = riner::flat_field_normalise(raw, flat, dark, &report);
    CHECK(std::isnan(rho.data[0]));
    CHECK(std::isnan(rho.data[3]));
    CHECK(rho.data[1] == std::numeric_limits<float>::infinity());
    CHECK(std::isnan(rho.data[4]));
    CHECK(rho.data[2] == doctest::Approx(-std::log(140.0 / 100.0)));
    CHECK(rho.data[5] == doctest::Approx(-std::log(70.0 / 100.0)));
    CHECK(report.invalid_readings == 4);
    CHECK(report.pixels_without_beam == 1);
    CHECK(report.pixels == 3);
  }

  TEST_CASE("light within the dark's noise is no light; the noise from each row of dark frames") {
    // Two rows of 40 pixels; 4 dark frames about 100, row 0 with a noise of 5 counts (plus one
    // hot pixel of 200) and a level that drifts from frame to frame by 20 (no noise of a
    // reading), row 1 with none. The threshold, 3 sigma sqrt(1 + 1/4), is 16.8 counts on row 0:
    // light of 10 over the dark there is no light (+inf, a metal's rays), light of 25 a reading;
    // on row 1 light of 2 is a reading.
    const std::size_t columns = 40, pixels = 2 * columns;
    const float b = std::sqrt(37.5f);  // -b, 0, b, 0: a variance of 25
    const float noise[4] = {-b, 0.0f, b, 0.0f};
    const float drift[4] = {-30.0f, -10.0f, 10.0f, 30.0f};
    Array darks({4, 2, columns});
    for (std::size_t f = 0; f < 4; ++f) {
      for (std::size_t c = 0; c < columns; ++c) {
        darks.data[f * pixels + c] =
            100.0f + drift[f] + noise[(f + c) % 4] * (c == 7 ? 40.0f : 1.0f);
        darks.data[f * pixels + columns + c] = 100.0f;
      }
    }
    Array flat({2, columns}, 1100.0f);
    // A dim beam, 200 over the dark (under e^4 times the threshold: a thick body's light, not a
    // metal's, lies within the noise there): only light at or below the dark is none.
    flat.data[9] = 300.0f;
    Array raw({1, 2, columns}, 600.0f);
    raw.data[3] = 110.0f;            // row 0: 10 over the dark
    raw.data[4] = 125.0f;            // row 0: 25 over it
    raw.data[9] = 110.0f;            // 10 over it under the weak beam
    raw.data[columns + 3] = 102.0f;  // row 1: 2 over it
    FlatFieldReport report;
    const Array rho = riner::flat_field_normalise(raw, flat, darks, &report);
    CHECK(rho.data[3] == std::numeric_limits<float>::infinity());
    CHECK(rho.data[4] == doctest::Approx(-std::log(25.0 / 1000.0)).epsilon(1e-5));
    CHECK(rho.data[columns + 3] == doctest::Approx(-std::log(2.0 / 1000.0)).epsilon(1e-5));
    CHECK(rho.data[9] == doctest::Approx(-std::log(10.0 / 200.0)).epsilon(1e-5));
    CHECK(report.invalid_readings == 1);
    CHECK(report.readings_in_dark_noise == 1);
    // The median over the rows of 5 (the hot pixel and the drift left out) and 0.
    CHECK(report.dark_noise == doctest::Approx(5.0).epsilon(1e-4));
    // One row alone (a slab, or --row) is read as in the whole stack.
    Array raw_row({1, 1, columns}), flat_row({1, columns}, 1100.0f), darks_row({4, 1, columns});
    flat_row.data[9] = 300.0f;
    std::copy(raw.data.begin(), raw.data.begin() + columns, raw_row.data.begin());
    for (std::size_t f = 0; f < 4; ++f) {
      std::copy(darks.data.begin() + f * pixels, darks.data.begin() + f * pixels + columns,
                darks_row.data.begin() + f * columns);
    }
    const Array rho_row = riner::flat_field_normalise(raw_row, flat_row, darks_row);
    for (std::size_t c = 0; c < columns; ++c) CHECK(rho_row.data[c] == rho.data[c]);
    // A single dark frame (or frames averaged before saving) says nothing of the noise: only
    // light at or below the dark is none, as before.
    Array one_dark({2, columns}, 100.0f);
    FlatFieldReport single;
    const Array rho_single = riner::flat_field_normalise(raw, flat, one_dark, &single);
    CHECK(rho_single.data[3] == doctest::Approx(-std::log(10.0 / 1000.0)).epsilon(1e-5));
    CHECK(single.dark_noise == 0.0);
    CHECK(single.invalid_readings == 0);
  }

  TEST_CASE("a flat field with beam on few of the pixels is named; one dead pixel is not") {
    // 40 pixels; the flat's beam on the first 20 only (a flat of another region, say).
    Array raw({2, 40});
    Array flat({40});
    for (std::size_t p = 0; p < 40; ++p) {
      flat.data[p] = p < 20 ? 1000.0f : 0.0f;
      raw.data[p] = raw.data[40 + p] = 500.0f;
    }
    FlatFieldReport report;
    riner::flat_field_normalise(raw, flat, Array{}, &report);
    CHECK(riner::pixels_without_beam_line(report) ==
          "note: 20 of the detector's 40 pixels (50.0%) have no beam in the flat field (at or "
          "below the dark): riner takes them for dead elements; check that the flat and dark "
          "fields are of this detector's region, binning and exposure");
    flat.data.assign(40, 1000.0f);
    flat.data[7] = 0.0f;  // 2.5%: a dead pixel
    riner::flat_field_normalise(raw, flat, Array{}, &report);
    CHECK(report.pixels_without_beam == 1);
    CHECK(riner::pixels_without_beam_line(report).empty());
  }

  TEST_CASE("a flat field of another exposure, or readings already -ln(I/I0), are named") {
    // 20 views x 64 pixels: an object on the middle 40, air at the ends; counts about 4000.
    Array raw({20, 64}), flat({64});
    for (std::size_t p = 0; p < 64; ++p) {
      flat.data[p] = 4000.0f;
      const double object = p >= 12 && p < 52 ? 1.5 : 0.0;
      for (std::size_t v = 0; v < 20; ++v) {
        raw.data[v * 64 + p] = static_cast<float>(4000.0 * std::exp(-object) + (v + p) % 3);
      }
    }
    FlatFieldReport report;
    riner::flat_field_normalise(raw, flat, Array{}, &report);
    CHECK(riner::air_level_line(report).empty());
    // A flat of ones (the air read -7.06 without a word).
    riner::flat_field_normalise(raw, Array({64}, 1.0f), Array{}, &report);
    CHECK(riner::air_level_line(report).find("note: the air reads -8.29") == 0);
    // Line integrals given as raw projections with the flat.
    Array rho = raw;
    for (float& x : rho.data) x = -std::log(x / 4000.0f) + 0.001f;
    riner::flat_field_normalise(rho, flat, Array{}, &report);
    CHECK(riner::air_level_line(report).find("note: even the least-attenuated elements read") == 0);
  }

  TEST_CASE("a frame of the wrong shape, or nothing valid, is an InputError saying which") {
    const Array raw({2, 2, 3}, 50.0f);
    auto message = [&](const Array& flat, const Array& dark) -> std::string {
      try {
        riner::flat_field_normalise(raw, flat, dark);
      } catch (const riner::InputError& e) {
        return e.what();
      }
      return "accepted";
    };
    CHECK(message(Array({3, 2}, 100.0f), Array()).find("the flat field is [3, 2]") == 0);
    CHECK(message(Array({2, 3}, 100.0f), Array({4, 3, 2}, 1.0f)).find("the dark field is") == 0);
    CHECK(message(Array({2, 3}, 100.0f), Array({2, 3}, 60.0f)).find("no projection reading") == 0);
    CHECK(message(Array({2, 3}, 100.0f), Array({0, 2, 3})).find("the dark field") == 0);
  }
}

TEST_SUITE("flat_field") {
  // A beam that weakens by 4% over 200 views, on a 40-element detector whose 8 outer elements
  // see air: flats before and after, Poisson-free readings.
  struct Drifting {
    Array raw{{200, 40}};
    Array rho_true{{200, 40}};
    Array before{{3, 40}};
    Array after{{2, 40}};
  };
  Drifting drifting_scan(double drop) {
    Drifting d;
    auto beam = [&](std::size_t e, double at) {  // at: position on the views' axis
      return (2000.0 + 20.0 * static_cast<double>(e)) * (1.0 - drop * (at + 0.5) / 200.0);
    };
    for (std::size_t e = 0; e < 40; ++e) {
      for (std::size_t f = 0; f < 3; ++f) d.before.data[f * 40 + e] = beam(e, -0.5);
      for (std::size_t f = 0; f < 2; ++f) d.after.data[f * 40 + e] = beam(e, 199.5);
      for (std::size_t v = 0; v < 200; ++v) {
        const bool air = e < 4 || e >= 36;
        const double rho = air ? 0.0 : 0.5 + 0.3 * std::sin(0.1 * v + 0.2 * e);
        d.rho_true.data[v * 40 + e] = static_cast<float>(rho);
        d.raw.data[v * 40 + e] =
            static_cast<float>(beam(e, static_cast<double>(v)) * std::exp(-rho));
      }
    }
    return d;
  }

  TEST_CASE("one detector row of a stack: a flat of one frame or of several, frames checked") {
    // 4 views of a 3 x 5 detector, a 2D geometry for row 1.
    const riner::Geometry g = riner::test::make_geometry(riner::GeometryType::kParallel2d, 4, 5, 1,
                                                         {5, 5}, 1.0, 1.0, M_PI);
    Array raw({4, 3, 5}), frame({3, 5}), frames({2, 3, 5});
    for (std::size_t i = 0; i < frame.size(); ++i) {
      frame.data[i] = 1000.0f + static_cast<float>(i);
      frames.data[i] = frame.data[i] - 1.0f;
      frames.data[frame.size() + i] = frame.data[i] + 1.0f;
    }
    for (std::size_t i = 0; i < raw.size(); ++i) {
      raw.data[i] = 0.5f * frame.data[i % frame.size()] * (1.0f + 0.01f * (i % 7));
    }
    // A single-TIFF flat is one frame, no stack axis: the same measurement as a stack of it.
    const riner::Scan one = riner::raw_scan(g, raw, frame, Array(), 1, "p");
    const riner::Scan two = riner::raw_scan(g, raw, frames, Array(), 1, "p");
    REQUIRE(one.measurement.shape == std::vector<std::size_t>{4, 5});
    for (std::size_t i = 0; i < one.measurement.size(); ++i) {
      CHECK(one.measurement.data[i] == doctest::Approx(two.measurement.data[i]).epsilon(1e-6));
    }
    // Frames of another detector are refused even where the row exists in both.
    const Array wrong({2, 4, 5}, 1000.0f);
    CHECK_THROWS_WITH_AS(riner::raw_scan(g, raw, wrong, Array(), 1, "p"),
                         "p: the flat field is [2, 4, 5]; it must be one frame of a view's shape "
                         "[3, 5] or a stack of them",
                         riner::InputError);
    CHECK_THROWS_WITH_AS(riner::raw_scan(g, raw, frame, Array({5}, 10.0f), 1, "p"),
                         "p: the dark field is [5]; it must be one frame of a view's shape [3, 5] "
                         "or a stack of them",
                         riner::InputError);
  }

  TEST_CASE("flats before and after: each view's flat interpolated, the drift measured") {
    const Drifting d = drifting_scan(0.04);
    const riner::FlatStack flats = riner::flats_before_after(d.before, d.after, d.raw.shape);
    REQUIRE(flats.frames.shape == std::vector<std::size_t>{5, 40});
    CHECK(flats.positions == std::vector<double>{-0.5, -0.5, -0.5, 199.5, 199.5});
    FlatFieldReport report;
    const Array rho =
        riner::flat_field_normalise(d.raw, flats.frames, Array(), &report, flats.positions);
    double worst = 0.0;
    for (std::size_t i = 0; i < rho.size(); ++i) {
      worst = std::max(worst, std::fabs(static_cast<double>(rho.data[i]) - d.rho_true.data[i]));
    }
    CHECK(worst < 1e-5);
    CHECK(report.flat_frames == 5);
    CHECK(report.flat_series == 2);
    CHECK(report.flat_change == doctest::Approx(-0.04 * 200.0 / 200.0).epsilon(0.02));
    CHECK_FALSE(riner::air_drifts(report));  // the flats followed the beam
    CHECK(riner::air_drift_line(report).empty());

    // The flats before alone (averaged, as riner did): the air reads the drift, and says so.
    FlatFieldReport one;
    const Array stale = riner::flat_field_normalise(d.raw, d.before, Array(), &one);
    CHECK(one.flat_series == 1);
    CHECK(one.air_first == doctest::Approx(0.002).epsilon(0.1));  // -ln(1 - 0.04 * 10 / 200)
    CHECK(one.air_last == doctest::Approx(0.0388).epsilon(0.05));
    CHECK(riner::air_drifts(one));
    CHECK(riner::air_drift_line(one).find("--flat-after") != std::string::npos);
    worst = 0.0;
    for (std::size_t i = 0; i < stale.size(); ++i) {
      worst = std::max(worst, std::fabs(static_cast<double>(stale.data[i]) - d.rho_true.data[i]));
    }
    CHECK(worst > 0.03);  // the last views read the drift as attenuation
  }

  TEST_CASE("a steady beam is not called drift, noisy or not; flats of two shapes are an error") {
    const Drifting steady = drifting_scan(0.0);
    FlatFieldReport report;
    (void)riner::flat_field_normalise(steady.raw, steady.before, Array(), &report);
    CHECK(report.air_first == doctest::Approx(0.0));
    CHECK_FALSE(riner::air_drifts(report));
    // With noise (1% per reading) and a drift under it, still nothing.
    Drifting noisy = drifting_scan(0.002);
    std::uint32_t state = 12345u;
    for (float& x : noisy.raw.data) {
      state = state * 1664525u + 1013904223u;
      x *= 1.0f + 0.01f * (static_cast<float>(state >> 8) / 16777216.0f - 0.5f) * 3.46f;
    }
    (void)riner::flat_field_normalise(noisy.raw, noisy.before, Array(), &report);
    CHECK_FALSE(riner::air_drifts(report));
    // A sample wider than the field: no element reads air, the least-attenuated ones read the
    // sample turning (0.34 then 0.61): no drift to measure, none claimed.
    Drifting wide = drifting_scan(0.0);
    for (std::size_t v = 0; v < 200; ++v) {
      for (std::size_t e = 0; e < 40; ++e) {
        const double rho =
            0.34 + 0.27 * static_cast<double>(v) / 199.0 + 0.01 * static_cast<double>(e % 5);
        wide.raw.data[v * 40 + e] = static_cast<float>(wide.before.data[e] * std::exp(-rho));
      }
    }
    (void)riner::flat_field_normalise(wide.raw, wide.before, Array(), &report);
    CHECK(report.air_drift_sigmas > riner::kAirDriftSigmas);  // the change is there
    CHECK_FALSE(riner::air_drifts(report));                   // but it is no air's
    CHECK_THROWS_AS(riner::flats_before_after(steady.before, Array({2, 30}), steady.raw.shape),
                    riner::InputError);
    // A position per frame, or an error.
    CHECK_THROWS_AS(riner::flat_field_normalise(steady.raw, steady.before, Array(), nullptr, {0.0}),
                    riner::InputError);
  }
}
