// The host-side pieces of FBP: taps, view weights, cosine weights, non-finite repair.
#include <doctest/doctest.h>

#include <cmath>
#include <complex>
#include <numeric>
#include <unsupported/Eigen/FFT>

#include "analytic/fbp_setup.hpp"
#include "riner/scan.hpp"
#include "support/geometries.hpp"

namespace {

// Frequency response of the taps (already times tau) at frequency f cycles/sample.
double response(const std::vector<double>& taps, double f) {
  const long n = static_cast<long>(taps.size() + 1) / 2;
  double sum = 0.0;
  for (long k = -(n - 1); k <= n - 1; ++k)
    sum += taps[static_cast<std::size_t>(k + n - 1)] * std::cos(2 * M_PI * f * k);
  return sum;
}

}  // namespace

TEST_SUITE("fbp_setup") {
  TEST_CASE("Ram-Lak taps: Kak & Slaney values and a ramp response") {
    const double tau = 0.5;
    const auto taps = riner::analytic::filter_taps(64, tau, riner::FbpFilter::kRamLak);
    REQUIRE(taps.size() == 127);
    CHECK(taps[63] == doctest::Approx(1.0 / (4.0 * tau)));
    CHECK(taps[64] == doctest::Approx(-1.0 / (M_PI * M_PI * tau)));
    CHECK(taps[65] == doctest::Approx(0.0));
    CHECK(taps[62] == taps[64]);
    // The band-limited ramp: response |f| / tau (per mm units), within truncation error.
    for (double f : {0.1, 0.25, 0.4})
      CHECK(response(taps, f) == doctest::Approx(f / tau).epsilon(0.02));
    CHECK(std::fabs(response(taps, 0.0)) < 0.01 / tau);
  }

  TEST_CASE("windows shape the ramp: Shepp-Logan sinc, Hann to zero at Nyquist") {
    const auto ramlak = riner::analytic::filter_taps(128, 1.0, riner::FbpFilter::kRamLak);
    const auto shepp = riner::analytic::filter_taps(128, 1.0, riner::FbpFilter::kSheppLogan);
    const auto hann = riner::analytic::filter_taps(128, 1.0, riner::FbpFilter::kHann);
    const double f = 0.3;
    CHECK(response(shepp, f) ==
          doctest::Approx(response(ramlak, f) * std::sin(M_PI * f) / (M_PI * f)).epsilon(0.01));
    CHECK(response(hann, f) ==
          doctest::Approx(response(ramlak, f) * 0.5 * (1 + std::cos(2 * M_PI * f))).epsilon(0.01));
    CHECK(std::fabs(response(hann, 0.5)) < 0.01);
  }

  TEST_CASE("view weights cover pi, whatever the angle list") {
    bool short_scan = true;
    // Fan beam, 360 views over [0, 2 pi): each view 2 pi / 360 / 2.
    auto fan = riner::test::make_geometry(riner::GeometryType::kFan2d, 360, 8, 1, {8, 8}, 1.0, 1.0);
    auto w = riner::analytic::view_weights(fan, &short_scan);
    CHECK_FALSE(short_scan);
    for (double x : w) CHECK(x == doctest::Approx(M_PI / 360.0));
    // Parallel beam over 0..180 degrees inclusive (like the tooth scan): the first and last
    // views see the same lines and share one step.
    auto par =
        riner::test::make_geometry(riner::GeometryType::kParallel2d, 181, 8, 1, {8, 8}, 1.0, 1.0);
    par.angles.clear();
    for (int i = 0; i <= 180; ++i) par.angles.push_back(i * M_PI / 180.0);
    w = riner::analytic::view_weights(par, &short_scan);
    CHECK(std::accumulate(w.begin(), w.end(), 0.0) == doctest::Approx(M_PI));
    CHECK(w[0] + w[180] == doctest::Approx(M_PI / 180.0));
    CHECK(w[90] == doctest::Approx(M_PI / 180.0));
    CHECK_FALSE(short_scan);
    // A 360 degree parallel scan counts every line twice: half weights.
    par.angles.clear();
    for (int i = 0; i < 100; ++i) par.angles.push_back(i * 2 * M_PI / 100.0);
    w = riner::analytic::view_weights(par, &short_scan);
    CHECK(w[17] == doctest::Approx(M_PI / 100.0));
    // Unsorted, irregular angles: still a partition of the period.
    fan.angles = {3.0, 0.5, 5.9, 1.0, 2.0};
    w = riner::analytic::view_weights(fan, &short_scan);
    CHECK(std::accumulate(w.begin(), w.end(), 0.0) == doctest::Approx(M_PI));
    CHECK(w[1] == doctest::Approx(0.5 * 0.5 * (0.5 + (0.5 + 2 * M_PI - 5.9))));
    // Two turns (720 degrees): each phase seen twice, every view an equal share, not a short
    // scan (before: the views paired up, half of them weighed 0 and the scan read as short).
    par.angles.clear();
    for (int i = 0; i < 360; ++i) par.angles.push_back(i * 4 * M_PI / 360.0);
    w = riner::analytic::view_weights(par, &short_scan);
    CHECK_FALSE(short_scan);
    for (double x : w) CHECK(x == doctest::Approx(M_PI / 360.0));
    // A repeated angle shares its place's weight.
    par.angles = {0.0, 0.5, 0.5, 1.0, 1.5, 2.0, 2.5};
    w = riner::analytic::view_weights(par, &short_scan);
    CHECK(w[1] == doctest::Approx(0.25));
    CHECK(w[2] == doctest::Approx(0.25));
    CHECK(std::accumulate(w.begin(), w.end(), 0.0) == doctest::Approx(M_PI));
    // A fan scan over half a turn is flagged.
    fan.angles.clear();
    for (int i = 0; i < 90; ++i) fan.angles.push_back(i * M_PI / 90.0);
    riner::analytic::view_weights(fan, &short_scan);
    CHECK(short_scan);
  }

  TEST_CASE(
      "non-finite repair: interpolated inside, constant at the ends, a lost view from "
      "the views beside it") {
    riner::Array m({3, 5}, std::vector<float>{1, NAN, NAN, 4, 5,               //
                                              INFINITY, 2, 3, -INFINITY, NAN,  //
                                              NAN, NAN, NAN, NAN, NAN});
    CHECK(riner::analytic::repair_non_finite(m, 5) == 10);
    CHECK(m.data == std::vector<float>{1, 2, 3, 4, 5, 2, 2, 3, 3, 3, 2, 2, 3, 3, 3});
    riner::Array between({3, 2}, std::vector<float>{1, 2, NAN, INFINITY, 3, 6});
    riner::analytic::repair_non_finite(between, 2);
    CHECK(between.data == std::vector<float>{1, 2, 2, 4, 3, 6});
    // A reading no line integral reaches (two of 1e19 made an FBP image of +-1e17).
    riner::Array corrupt({1, 3}, std::vector<float>{1, 1e19f, 3});
    CHECK(riner::analytic::repair_non_finite(corrupt, 3) == 1);
    CHECK(corrupt.data == std::vector<float>{1, 2, 3});
    riner::Array nothing({2, 2}, NAN);
    riner::analytic::repair_non_finite(nothing, 2);
    CHECK(nothing.data == std::vector<float>{0, 0, 0, 0});
  }

  TEST_CASE("spikes far beyond every view's readings are repaired; dense objects and scales kept") {
    // Five readings of 1e5 among readings up to 3 (under the absolute 1e6) made FBP's image -52
    // dB without a word (the audit). A reading counts as a spike beyond 100 times the median
    // view's largest, and never under rho = 50.
    const std::size_t views = 40, n_u = 30;
    riner::Array m({views, n_u});
    for (std::size_t v = 0; v < views; ++v) {
      for (std::size_t j = 0; j < n_u; ++j) {
        m.data[v * n_u + j] = 3.0f * std::sin(static_cast<float>(j) / n_u * 3.14159f);
      }
      m.data[v * n_u + 7] = 20.0f;  // a dense wire in every view
    }
    m.data[3 * n_u + 12] = 45.0f;  // one reading high, but under rho = 50
    riner::Array spiked = m;
    for (std::size_t k : {5u, 77u, 301u, 640u, 1111u}) spiked.data[k] = 1e5f;
    CHECK(riner::largest_reading(spiked, views) == doctest::Approx(2000.0f));
    CHECK(riner::analytic::repair_non_finite(spiked, n_u) == 5);
    for (std::size_t k : {5u, 77u, 301u, 640u, 1111u}) CHECK(spiked.data[k] < 25.0f);
    CHECK(spiked.data[3 * n_u + 12] == 45.0f);
    CHECK(spiked.data[10 * n_u + 7] == 20.0f);
    // The same scan stored x1000: nothing is a spike.
    riner::Array scaled = m;
    for (float& x : scaled.data) x *= 1000.0f;
    CHECK(riner::analytic::repair_non_finite(scaled, n_u) == 0);
    // Readings all small: the limit stays at rho = 50.
    riner::Array faint = m;
    for (float& x : faint.data) x *= 0.001f;
    CHECK(riner::largest_reading(faint, views) == doctest::Approx(50.0f));
  }

  TEST_CASE("non-finite repair: a dead detector row takes the rows beside it in each view") {
    // Before: 0, which FBP reconstructs as a slice of air (a parallel stack's dead row 20:
    // 0.0198 rms off the noise-free slice against 0.0120 interpolated, riner simulate).
    riner::Array m({2, 4, 2}, std::vector<float>{1, 2, NAN, NAN, 3, 6, 4, 4,  //
                                                 NAN, NAN, 5, 5, NAN, NAN, 7, 9});
    CHECK(riner::analytic::repair_non_finite(m, 2, 4) == 6);
    CHECK(m.data == std::vector<float>{1, 2, 2, 4, 3, 6, 4, 4,  //
                                       5, 5, 5, 5, 6, 7, 7, 9});
  }

  TEST_CASE("cosine weights: 1 on the central ray, SDD / distance elsewhere") {
    auto fan = riner::test::make_geometry(riner::GeometryType::kFan2d, 1, 3, 1, {8, 8}, 10.0, 1.0);
    riner::Array m({1, 3}, 1.0f);
    riner::analytic::cosine_weight(m, fan);
    const double sdd = fan.source_origin_mm + fan.origin_detector_mm;
    CHECK(m.data[1] == doctest::Approx(1.0));
    CHECK(m.data[0] == doctest::Approx(sdd / std::sqrt(sdd * sdd + 100.0)));
  }
}
