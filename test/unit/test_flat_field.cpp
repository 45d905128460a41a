// Raw projections to the measurement: -ln((I - D) / (F - D)), frames averaged, invalid
// readings NaN and counted.
#include <doctest/doctest.h>

#include <cmath>

#include "riner/error.hpp"
#include "riner/flat_field.hpp"

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

  TEST_CASE("readings at or below the dark and pixels without beam become NaN, counted") {
    // Pixel 0: flat equals dark (no beam): both of its readings invalid. Pixel 1: one reading
    // below the dark, one NaN. Pixel 2: valid, reading above the flat (rho < 0 is kept).
    const Array raw({2, 3}, {50.0f, 5.0f, 150.0f, 60.0f, NAN, 80.0f});
    const Array flat({3}, {10.0f, 100.0f, 110.0f});
    const Array dark({3}, {10.0f, 10.0f, 10.0f});
    FlatFieldReport report;
    const Array rho = riner::flat_field_normalise(raw, flat, dark, &report);
    CHECK(std::isnan(rho.data[0]));
    CHECK(std::isnan(rho.data[3]));
    CHECK(std::isnan(rho.data[1]));
    CHECK(std::isnan(rho.data[4]));
    CHECK(rho.data[2] == doctest::Approx(-std::log(140.0 / 100.0)));
    CHECK(rho.data[5] == doctest::Approx(-std::log(70.0 / 100.0)));
    CHECK(report.invalid_readings == 4);
    CHECK(report.pixels_without_beam == 1);
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
