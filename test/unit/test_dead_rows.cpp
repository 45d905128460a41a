// Detector rows that read nothing (model/dead_rows.hpp): filled for training from the rows
// beside them in each view, element by element; nothing else changes.
#include <doctest/doctest.h>

#include <cmath>

#include "model/dead_rows.hpp"

namespace {

riner::Geometry stack_geometry(std::size_t rows, std::size_t columns, std::size_t views) {
  riner::Geometry g;
  g.type = riner::GeometryType::kParallel3d;
  g.n_u = columns;
  g.n_v = rows;
  g.volume_shape = {rows, columns, columns};
  for (std::size_t v = 0; v < views; ++v) g.angles.push_back(M_PI * static_cast<double>(v) / static_cast<double>(views));
  return g;
}

// Reading (v, r, c) = v + 10 r + 100 c.
riner::Array ramp(const riner::Geometry& g) {
  riner::Array a({g.n_views(), g.n_v, g.n_u});
  for (std::size_t v = 0; v < g.n_views(); ++v)
    for (std::size_t r = 0; r < g.n_v; ++r)
      for (std::size_t c = 0; c < g.n_u; ++c) a(v, r, c) = static_cast<float>(v + 10 * r + 100 * c);
  return a;
}

}  // namespace

TEST_SUITE("dead rows") {
  TEST_CASE("a dead row takes the line between its neighbours, an end row its one neighbour") {
    const riner::Geometry g = stack_geometry(8, 5, 3);
    riner::Array a = ramp(g);
    const riner::Array before = a;
    for (std::size_t v = 0; v < 3; ++v) {
      for (std::size_t c = 0; c < 5; ++c) {
        a(v, 3, c) = NAN;  // rows 3 and 4: a band; row 0: the detector's end
        a(v, 4, c) = INFINITY;
        a(v, 0, c) = NAN;
      }
    }
    a(1, 2, 2) = NAN;  // a dead element beside the band, in one view
    a(0, 6, 1) = NAN;  // and a reading that stays NaN: row 6 is not dead
    const std::vector<std::size_t> filled = riner::model::fill_dead_rows(a, g);
    CHECK(filled == std::vector<std::size_t>{0, 3, 4});
    for (std::size_t v = 0; v < 3; ++v) {
      for (std::size_t c = 0; c < 5; ++c) {
        CAPTURE(v);
        CAPTURE(c);
        CHECK(a(v, 0, c) == before(v, 1, c));
        if (v == 1 && c == 2) {
          // Row 2 reads nothing there: rows 3 and 4 take row 5's reading.
          CHECK(a(v, 3, c) == before(v, 5, c));
          CHECK(std::isnan(a(v, 2, c)));
        } else {
          // The ramp is linear in the row: the line between rows 2 and 5 is the ramp itself.
          CHECK(a(v, 3, c) == doctest::Approx(before(v, 3, c)));
          CHECK(a(v, 4, c) == doctest::Approx(before(v, 4, c)));
        }
      }
    }
    CHECK(std::isnan(a(0, 6, 1)));
  }

  TEST_CASE("a slice's scan, a scan with no dead row or only dead rows is left as it was") {
    riner::Geometry g = stack_geometry(4, 5, 3);
    riner::Array a = ramp(g);
    CHECK(riner::model::fill_dead_rows(a, g).empty());
    for (float& x : a.data) x = NAN;
    CHECK(riner::model::fill_dead_rows(a, g).empty());
    g.type = riner::GeometryType::kParallel2d;
    g.n_v = 1;
    riner::Array slice({3, 5}, NAN);
    CHECK(riner::model::fill_dead_rows(slice, g).empty());
  }
}
