// Daubechies' filters from the spectral factorisation, and the periodised 2D transform built on
// them (destripe/wavelets.hpp): the conditions that make a filter an orthogonal wavelet's, the
// closed form of db2, and an exact round trip.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "destripe/wavelets.hpp"

TEST_CASE("each Daubechies filter is an orthogonal wavelet's with order vanishing moments") {
  for (int order = 1; order <= 12; ++order) {
    CAPTURE(order);
    const std::vector<double> h = riner::stripes::daubechies_filter(order);
    REQUIRE(h.size() == static_cast<std::size_t>(2 * order));
    double sum = 0.0;
    for (double x : h) sum += x;
    CHECK(sum == doctest::Approx(std::sqrt(2.0)).epsilon(1e-10));
    // Orthonormal to its own shifts by two.
    for (std::size_t shift = 0; shift < h.size(); shift += 2) {
      double dot = 0.0;
      for (std::size_t n = 0; n + shift < h.size(); ++n) dot += h[n] * h[n + shift];
      CHECK(std::fabs(dot - (shift == 0 ? 1.0 : 0.0)) < 1e-9);
    }
    // The high-pass filter annihilates polynomials of degree below the order: sum over n of
    // (-1)^n n^p h[n] = 0 (relative to the sum of the magnitudes, which grows as n^p).
    for (int p = 0; p < order; ++p) {
      double moment = 0.0, scale = 0.0;
      for (std::size_t n = 0; n < h.size(); ++n) {
        const double term = (n % 2 == 0 ? 1.0 : -1.0) * std::pow(static_cast<double>(n), p) * h[n];
        moment += term;
        scale += std::fabs(term);
      }
      CAPTURE(p);
      CHECK(std::fabs(moment) < 1e-8 * scale);
    }
  }
  const std::vector<double> db2 = riner::stripes::daubechies_filter(2);
  const double s3 = std::sqrt(3.0), norm = 4.0 * std::sqrt(2.0);
  CHECK(db2[0] == doctest::Approx((1.0 + s3) / norm).epsilon(1e-12));
  CHECK(db2[1] == doctest::Approx((3.0 + s3) / norm).epsilon(1e-12));
  CHECK(db2[2] == doctest::Approx((3.0 - s3) / norm).epsilon(1e-12));
  CHECK(db2[3] == doctest::Approx((1.0 - s3) / norm).epsilon(1e-12));
  CHECK_THROWS(riner::stripes::daubechies_filter(0));
  CHECK_THROWS(riner::stripes::daubechies_filter(13));
}

TEST_CASE("three levels of the periodised 2D transform keep the energy and invert exactly") {
  // Short levels (6 x 8 at the third) against a 18-tap filter: the periodised filter wraps more
  // than once there and must still be orthonormal.
  const std::size_t rows = 48, columns = 64;
  std::mt19937 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::vector<double> values(rows * columns);
  for (double& x : values) x = normal(rng);
  const std::vector<double> original = values;
  double energy = 0.0;
  for (double x : values) energy += x * x;
  for (int order : {1, 5, 9}) {
    CAPTURE(order);
    const std::vector<double> h = riner::stripes::daubechies_filter(order);
    values = original;
    for (int l = 0; l < 3; ++l) {
      riner::stripes::wavelet_level(values, rows >> l, columns >> l, columns, h);
    }
    double transformed = 0.0;
    for (double x : values) transformed += x * x;
    CHECK(transformed == doctest::Approx(energy).epsilon(1e-12));
    for (int l = 2; l >= 0; --l) {
      riner::stripes::inverse_wavelet_level(values, rows >> l, columns >> l, columns, h);
    }
    double worst = 0.0;
    for (std::size_t i = 0; i < values.size(); ++i) {
      worst = std::max(worst, std::fabs(values[i] - original[i]));
    }
    CHECK(worst < 1e-11);
  }
}

TEST_CASE("a stripe lands in the band of details across columns, at the zero frequency") {
  // An image constant along the rows but for one column: after a level, its details across
  // columns sit in the [low rows][high columns] quadrant, identical down each column.
  const std::size_t rows = 16, columns = 16;
  std::vector<double> values(rows * columns, 1.0);
  for (std::size_t r = 0; r < rows; ++r) values[r * columns + 7] += 0.5;
  riner::stripes::wavelet_level(values, rows, columns, columns, riner::stripes::daubechies_filter(3));
  double elsewhere = 0.0;
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < columns; ++c) {
      if (r >= rows / 2) elsewhere = std::max(elsewhere, std::fabs(values[r * columns + c]));
      if (r < rows / 2 && c >= columns / 2) {
        CHECK(values[r * columns + c] == doctest::Approx(values[c]).epsilon(1e-12));
      }
    }
  }
  CHECK(elsewhere < 1e-12);
}
