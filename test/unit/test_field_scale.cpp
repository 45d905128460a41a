// The field's scale: a power of two for scans far from the usual attenuation, 1 for the rest.
#include <doctest/doctest.h>

#include <cmath>

#include "model/field_scale.hpp"
#include "support/geometries.hpp"

TEST_SUITE("field_scale") {
  TEST_CASE("typical mu from the median view's largest reading; a power of two outside the band") {
    auto g = riner::test::make_geometry(riner::GeometryType::kParallel2d, 4, 10, 1, {100, 100}, 1.0,
                                        1.0);
    riner::Array m({4, 10}, 0.0f);
    // Views' largest readings 1, 2, 3 and a spike of 1000: the median view reads 3.
    for (std::size_t v = 0; v < 4; ++v) m.data[v * 10 + 5] = v < 3 ? 1.0f + v : 1000.0f;
    CHECK(riner::model::typical_mu(m, g) == doctest::Approx(3.0 / 100.0));
    CHECK(riner::model::field_per_mu(riner::model::typical_mu(m, g)) ==
          1.0);                                      // 0.03 /mm: inside the band
    g.voxel_mm = 1.0 / 1024.0;                       // micrometre voxels: 30.7 /mm
    const double per_mu = riner::model::field_per_mu(riner::model::typical_mu(m, g));
    CHECK(per_mu == std::ldexp(1.0, -11));
    CHECK(riner::model::typical_mu(m, g) * per_mu >= riner::model::kLeastTypicalMu);
    CHECK(riner::model::typical_mu(m, g) * per_mu <= riner::model::kMostTypicalMu);
    for (float& x : m.data) x *= 1e-6f;  // nearly transparent
    g.voxel_mm = 1.0;
    CHECK(riner::model::field_per_mu(riner::model::typical_mu(m, g)) == std::ldexp(1.0, 19));
    m = riner::Array({4, 10}, 0.0f);  // reads nothing: left alone
    CHECK(riner::model::field_per_mu(riner::model::typical_mu(m, g)) == 1.0);
  }

  TEST_CASE("lengths divided: every length, nothing else") {
    auto g =
        riner::test::make_geometry(riner::GeometryType::kCone3d, 8, 10, 6, {6, 8, 8}, 0.5, 0.25);
    g.source_origin_mm = 300.0;
    g.origin_detector_mm = 200.0;
    g.grid_centre_z_mm = 3.0;
    g.offset_u = 1.5;
    const riner::Geometry d = riner::model::lengths_divided(g, 0.25);
    CHECK(d.pitch_u == 4.0 * g.pitch_u);
    CHECK(d.pitch_v == 4.0 * g.pitch_v);
    CHECK(d.voxel_mm == 4.0 * g.voxel_mm);
    CHECK(d.source_origin_mm == 1200.0);
    CHECK(d.origin_detector_mm == 800.0);
    CHECK(d.grid_centre_z_mm == 12.0);
    CHECK(d.offset_u == 1.5);  // in elements
    CHECK(d.angles == g.angles);
  }
}
