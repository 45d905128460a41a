// Stuck detector elements (model/stuck_elements.hpp): a row, a column and a lone pixel that
// read a steady value while the object turns are found; the live elements, the air beside the
// object's silhouette and an element with non-finite readings are not.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "model/stuck_elements.hpp"

namespace {

// 90 views over 2 pi of a ball off the axis, seen by a 40 x 24 parallel detector, with noise.
riner::Scan ball_scan() {
  riner::Scan scan;
  riner::Geometry& g = scan.geometry;
  g.type = riner::GeometryType::kParallel3d;
  g.n_u = 40;
  g.n_v = 24;
  g.volume_shape = {24, 40, 40};
  for (int v = 0; v < 90; ++v) g.angles.push_back(2.0 * M_PI * v / 90.0);
  scan.measurement = riner::Array({90, 24, 40});
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0.0, 0.002);
  for (std::size_t v = 0; v < 90; ++v) {
    const double centre_u = 19.5 + 6.0 * std::cos(g.angles[v]);
    for (std::size_t r = 0; r < 24; ++r) {
      for (std::size_t u = 0; u < 40; ++u) {
        const double du = static_cast<double>(u) - centre_u, dv = static_cast<double>(r) - 11.5;
        const double d2 = 1.0 - (du * du + dv * dv) / 100.0;  // radius 10 elements
        scan.measurement(v, r, u) =
            static_cast<float>((d2 > 0.0 ? 2.0 * std::sqrt(d2) : 0.0) + noise(rng));
      }
    }
  }
  return scan;
}

}  // namespace

TEST_SUITE("stuck elements") {
  TEST_CASE("a stuck row, column and pixel inside the shadow are found; nothing else") {
    riner::Scan scan = ball_scan();
    for (std::size_t v = 0; v < 90; ++v) {
      for (std::size_t u = 0; u < 40; ++u) scan.measurement(v, 10, u) = 0.0f;  // at the flat
      for (std::size_t r = 0; r < 24; ++r) scan.measurement(v, r, 21) = 2.5f;  // dark
      scan.measurement(v, 14, 16) = 1.0f;
      scan.measurement(v, 5, 22) = NAN;  // dead already
    }
    const std::vector<std::uint8_t> stuck = riner::model::stuck_elements(scan, 0.002);
    int row = 0, column = 0, others = 0;
    for (std::size_t r = 0; r < 24; ++r) {
      for (std::size_t u = 0; u < 40; ++u) {
        if (!stuck[r * 40 + u]) continue;
        if (r == 10) {
          ++row;
        } else if (u == 21) {
          ++column;
        } else if (!(r == 14 && u == 16)) {
          ++others;
          MESSAGE("flagged (" << r << ", " << u << ")");
        }
      }
    }
    CHECK(stuck[14 * 40 + 16] == 1);
    CHECK(stuck[5 * 40 + 22] == 0);
    // Where the ball's shadow sweeps across them (columns 4..35 of row 10; rows 2..21 of column
    // 21): most; outside it the neighbours are steady air too, and stay unjudged.
    CHECK(row >= 24);
    CHECK(column >= 14);
    CHECK(others == 0);
  }

  TEST_CASE("the unchanged scan has no stuck element; noise-level neighbours are not judged") {
    const std::vector<std::uint8_t> stuck = riner::model::stuck_elements(ball_scan(), 0.002);
    int flagged = 0;
    for (std::uint8_t s : stuck) flagged += s;
    CHECK(flagged == 0);
    // With a noise sigma as large as the object, nothing is judged.
    riner::Scan scan = ball_scan();
    for (std::size_t v = 0; v < 90; ++v) scan.measurement(v, 14, 16) = 1.0f;
    for (std::uint8_t s : riner::model::stuck_elements(scan, 1.0)) CHECK(s == 0);
  }

  TEST_CASE("a band of 6 dead columns (a module) inside the shadow is found; air is not") {
    // The stuck rule's neighbours at 1 or 2 elements lie inside such a band: before, none of
    // it was found (20 dead columns of a 200-column scan: the axis found 13.6 px off, 15.4 dB).
    riner::Scan scan = ball_scan();
    for (std::size_t v = 0; v < 90; ++v) {
      for (std::size_t r = 0; r < 24; ++r) {
        for (std::size_t u = 14; u < 20; ++u) scan.measurement(v, r, u) = 0.0f;
      }
    }
    const std::vector<std::uint8_t> stuck = riner::model::stuck_elements(scan, 0.002);
    int band = 0, others = 0;
    for (std::size_t r = 0; r < 24; ++r) {
      for (std::size_t u = 0; u < 40; ++u) {
        if (!stuck[r * 40 + u]) continue;
        if (u >= 14 && u < 20) {
          ++band;
        } else {
          ++others;
        }
      }
    }
    // Every row the ball's shadow crosses on both sides of the band (rows 4 to 19 at least).
    CHECK(band >= 16 * 6);
    CHECK(others == 0);
    // The air beside the ball, steady out to the detector's ends, is never a band.
    for (std::size_t r = 0; r < 24; ++r) {
      CHECK(stuck[r * 40 + 0] == 0);
      CHECK(stuck[r * 40 + 39] == 0);
    }
  }

  TEST_CASE("air beside or between failing elements is never stuck") {
    // Rows 0 and 23 lie outside the ball's shadow: air in every view. Elements of them change
    // their reading half-way through the scan (a response that drifts, an element dying). The
    // 7 air columns between elements 10 and 18 of row 0, with a varying column either side,
    // were taken for a dead module; element 22 of row 23 between elements 20 and 24, and the
    // elements of rows 1 and 22 between a failing element and the ball's shadow, for stuck.
    riner::Scan scan = ball_scan();
    for (std::size_t v = 45; v < 90; ++v) {
      scan.measurement(v, 0, 10) += 0.5f;
      scan.measurement(v, 0, 18) -= 0.3f;
      scan.measurement(v, 23, 20) += 0.4f;
      scan.measurement(v, 23, 24) -= 0.4f;
    }
    const std::vector<std::uint8_t> stuck = riner::model::stuck_elements(scan, 0.002);
    for (std::size_t e = 0; e < stuck.size(); ++e) {
      CAPTURE(e);
      CHECK(stuck[e] == 0);
    }
  }
}
