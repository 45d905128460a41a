// The ring simulation protocol (METHOD.md §4): exact counts, reproducibility, noise statistics.
#include <doctest/doctest.h>

#include <cmath>

#include "riner/error.hpp"
#include "riner/simulate.hpp"
#include "simulation/random.hpp"
#include "support/geometries.hpp"

TEST_SUITE("simulation") {
  TEST_CASE("responses by rows x columns: a product of row and column factors, in range") {
    const riner::Geometry g = riner::test::small_cone3d();  // 37 rows x 61 columns
    riner::RingModel model;
    model.seed = 3;
    model.pattern = riner::ResponsePattern::kRowsTimesColumns;
    const riner::Array alpha = riner::draw_responses(g, model);
    REQUIRE(alpha.shape == std::vector<std::size_t>{37, 61});
    auto at = [&](std::size_t r, std::size_t c) { return double(alpha.data[r * 61 + c]); };
    int dead = 0;
    for (float a : alpha.data) {
      dead += a == 0.0f;
      if (a != 0.0f) {
        CHECK(a >= 0.75f * (1 - 1e-6f));
        CHECK(a <= 1.25f * (1 + 1e-6f));
      }
    }
    CHECK(dead == 2);
    // Rank one wherever all four corners are live: a(r, c) a(s, d) = a(r, d) a(s, c).
    int checked = 0;
    for (std::size_t r = 0; r + 5 < 37; r += 3) {
      for (std::size_t c = 0; c + 7 < 61; c += 4) {
        const double p = at(r, c) * at(r + 5, c + 7);
        const double q = at(r, c + 7) * at(r + 5, c);
        if (p == 0.0 || q == 0.0) continue;
        CHECK(p == doctest::Approx(q).epsilon(1e-6));
        ++checked;
      }
    }
    CHECK(checked > 100);
    riner::Geometry flat = riner::test::small_fan2d();
    CHECK_THROWS_WITH(riner::draw_responses(flat, model),
                      doctest::Contains("rows x columns need a 3D detector"));
  }

  TEST_CASE("responses follow the protocol exactly: 375 non-ideal, 2 dead, 123 ideal of 500") {
    const riner::Geometry g = riner::preset_geometry("fan2d-paper");
    riner::RingModel model;
    model.seed = 7;
    const riner::Array alpha = riner::draw_responses(g, model);
    REQUIRE(alpha.shape == std::vector<std::size_t>{500});
    int dead = 0, ideal = 0, nonideal = 0;
    for (float a : alpha.data) {
      if (a == 0.0f) {
        ++dead;
      } else if (a == 1.0f) {
        ++ideal;
      } else {
        ++nonideal;
        CHECK(a >= 0.75f);
        CHECK(a <= 1.25f);
      }
    }
    CHECK(dead == 2);
    CHECK(nonideal == 375);
    CHECK(ideal == 123);
  }

  TEST_CASE("same seed, same draws; another seed, other draws") {
    const riner::Geometry g = riner::preset_geometry("fan2d-paper");
    riner::RingModel model;
    model.seed = 3;
    const riner::Array a = riner::draw_responses(g, model);
    CHECK(riner::draw_responses(g, model).data == a.data);
    model.seed = 4;
    CHECK(riner::draw_responses(g, model).data != a.data);
    const riner::Array clean({360, 500}, 2.0f);
    model.seed = 3;
    const riner::Array m1 = riner::corrupt_measurement(clean, a, model);
    CHECK(riner::corrupt_measurement(clean, a, model).data == m1.data);
  }

  TEST_CASE("3D: dead rows and columns are whole") {
    auto g =
        riner::test::make_geometry(riner::GeometryType::kCone3d, 4, 30, 20, {8, 16, 16}, 2.0, 1.0);
    riner::RingModel model;
    model.dead_rows = 1;
    model.dead_columns = 2;
    model.dead_elements = 3;
    const riner::Array alpha = riner::draw_responses(g, model);
    REQUIRE(alpha.shape == std::vector<std::size_t>{20, 30});
    int dead = 0, full_rows = 0, full_columns = 0;
    for (float a : alpha.data) dead += a == 0.0f;
    for (std::size_t r = 0; r < 20; ++r) {
      bool all = true;
      for (std::size_t u = 0; u < 30; ++u) all = all && alpha(r, u) == 0.0f;
      full_rows += all;
    }
    for (std::size_t u = 0; u < 30; ++u) {
      bool all = true;
      for (std::size_t r = 0; r < 20; ++r) all = all && alpha(r, u) == 0.0f;
      full_columns += all;
    }
    CHECK(full_rows == 1);
    CHECK(full_columns == 2);
    CHECK(dead == 30 + 2 * 20 - 2 + 3);  // the row and the columns cross twice
    CHECK_THROWS_AS(riner::draw_responses(riner::preset_geometry("fan2d-paper"), model),
                    riner::InputError);
  }

  TEST_CASE("without noise, rho = p - ln(alpha), and dead elements read +inf") {
    const riner::Array clean({2, 3}, std::vector<float>{1, 2, 3, 4, 5, 6});
    const riner::Array alpha({3}, std::vector<float>{0.5f, 0.0f, 1.0f});
    riner::RingModel model;
    model.photons = 0.0;
    const riner::Array m = riner::corrupt_measurement(clean, alpha, model);
    CHECK(m(0, 0) == doctest::Approx(1.0 - std::log(0.5)));
    CHECK(std::isinf(m(1, 1)));
    CHECK(m(1, 2) == 6.0f);
    // With photons, dead elements still read +inf.
    model.photons = 1e7;
    CHECK(std::isinf(riner::corrupt_measurement(clean, alpha, model)(0, 1)));
  }

  TEST_CASE("Poisson draws have the right mean and variance at small and large means") {
    riner::sim::Random rng(11);
    for (double mean : {0.5, 3.0, 9.9, 10.0, 250.0, 2e5}) {
      CAPTURE(mean);
      const int n = 40000;
      double sum = 0.0, sum_sq = 0.0;
      for (int i = 0; i < n; ++i) {
        const double k = static_cast<double>(rng.poisson(mean));
        sum += k;
        sum_sq += k * k;
      }
      const double m = sum / n;
      const double var = sum_sq / n - m * m;
      // Five standard errors: the mean's is sqrt(mean / n), the variance's ~ mean sqrt(2 / n).
      CHECK(std::fabs(m - mean) < 5.0 * std::sqrt(mean / n));
      CHECK(std::fabs(var - mean) < 5.0 * mean * std::sqrt(2.0 / n) + 5.0 * std::sqrt(mean / n));
    }
  }

  TEST_CASE("noise level: rho's spread matches 1 / sqrt(photons reaching the detector)") {
    const riner::Array clean({20000, 1}, 4.0f);
    const riner::Array alpha({1}, 1.0f);
    riner::RingModel model;
    const riner::Array m = riner::corrupt_measurement(clean, alpha, model);
    double sum = 0.0, sum_sq = 0.0;
    for (float v : m.data) {
      sum += v;
      sum_sq += static_cast<double>(v) * v;
    }
    const double mean = sum / 20000.0;
    const double sd = std::sqrt(sum_sq / 20000.0 - mean * mean);
    const double expected_sd = 1.0 / std::sqrt(1e7 * std::exp(-4.0));
    CHECK(mean == doctest::Approx(4.0).epsilon(1e-3));
    CHECK(sd == doctest::Approx(expected_sd).epsilon(0.05));
  }

  TEST_CASE("presets and bad models") {
    const riner::Geometry cone = riner::preset_geometry("cone3d-paper");
    CHECK(cone.measurement_shape() == std::vector<std::size_t>{360, 200, 300});
    CHECK(cone.volume_shape == std::vector<std::size_t>{100, 256, 256});
    CHECK_THROWS_AS(riner::preset_geometry("fan3d"), riner::InputError);
    riner::RingModel bad;
    bad.alpha_min = 0.0;
    CHECK_THROWS_AS(bad.validate(), riner::InputError);
    bad = riner::RingModel();
    bad.nonideal_fraction = 1.5;
    CHECK_THROWS_AS(bad.validate(), riner::InputError);
  }
}
