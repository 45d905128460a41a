// The reference projector: exact on simple cases, adjoint to machine precision, and accurate
// against the exact line integrals of the Shepp-Logan phantom.
#include <doctest/doctest.h>

#include <random>

#include "reference/joseph_walk.hpp"
#include "reference/project_ref.hpp"
#include "riner/phantom.hpp"
#include "riner/rays.hpp"
#include "riner/simulate.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"
#include "support/geometries.hpp"

namespace {

double inner(const std::vector<double>& a, const std::vector<double>& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += a[i] * b[i];
  return s;
}

std::vector<double> random_vector(std::size_t n, std::uint64_t salt) {
  std::mt19937_64 rng(riner::test::seed() + salt);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<double> v(n);
  for (double& x : v) x = u(rng);
  return v;
}

double relative_rms(const riner::Array& got, const riner::Array& want) {
  return riner::test::compare(got.data, want.data).rms_rel;
}

}  // namespace

TEST_SUITE("projector_ref") {
  TEST_CASE("the walk stays inside the grid at views of exactly 0 and 90 degrees") {
    // At 90 degrees cos is 6e-17: rounding put a ray's crossing on the grid's far edge itself,
    // and the 2D walk read (and the adjoint wrote) one row past the volume.
    for (riner::Geometry g : {riner::test::small_parallel2d(), riner::test::small_parallel3d(),
                              riner::test::small_fan2d(), riner::test::small_cone3d()}) {
      CAPTURE(std::string(riner::geometry_type_name(g.type)));
      g.uniform_angles = riner::UniformAngles{30, 0.0, M_PI};
      g.angles = riner::uniform_angles(*g.uniform_angles);
      const riner::ref::GridIndexSpace grid(g);
      const std::size_t voxels = riner::shape_size(g.volume_shape);
      const std::size_t rows = g.is_3d() ? g.n_v : 1;
      std::size_t outside = 0;
      for (std::size_t view = 0; view < g.n_views(); ++view) {
        for (std::size_t row = 0; row < rows; ++row) {
          for (std::size_t u = 0; u < g.n_u; ++u) {
            const riner::Ray ray =
                riner::detector_ray(g, view, static_cast<double>(u), static_cast<double>(row));
            riner::ref::joseph_walk(grid, ray,
                                    [&](std::size_t i, double) { outside += i >= voxels; });
          }
        }
      }
      CHECK(outside == 0);
    }
  }

  TEST_CASE("a constant image projects to its chord lengths") {
    // Parallel view 0: vertical rays; through a 16 x 10 grid of 0.5 mm the chord is 8 mm.
    auto g =
        riner::test::make_geometry(riner::GeometryType::kParallel2d, 1, 8, 1, {16, 10}, 0.5, 0.5);
    g.angles = {0.0};
    const std::vector<double> out = riner::ref::project(g, std::vector<double>(160, 0.25));
    for (std::size_t j = 1; j + 1 < 8; ++j) CHECK(out[j] == doctest::Approx(0.25 * 8.0));
  }

  TEST_CASE("adjoint: <Ax, y> = <x, A^T y> in double for every geometry type") {
    for (const riner::Geometry& g :
         {riner::test::small_fan2d(), riner::test::small_parallel2d(), riner::test::small_cone3d(),
          riner::test::small_parallel3d()}) {
      CAPTURE(std::string(riner::geometry_type_name(g.type)));
      const auto x = random_vector(riner::shape_size(g.volume_shape), 1);
      const auto y = random_vector(riner::shape_size(g.measurement_shape()), 2);
      const double ax_y = inner(riner::ref::project(g, x), y);
      const double x_aty = inner(x, riner::ref::backproject_adjoint(g, y));
      // Same traversal both ways: equal up to summation order (1e-12 relative).
      CHECK(std::fabs(ax_y - x_aty) <= 1e-12 * std::fabs(ax_y));
    }
  }

  TEST_CASE("Joseph vs exact Shepp-Logan line integrals: fan2d-paper") {
    // What is left is the raster's own error at the ellipses' edges (first order in the pixel
    // size: 1.5% on the 1 mm grid, 0.75% on 0.5 mm), not the projector's. The simulator
    // therefore projects Shepp-Logan analytically; here the raster is 2x finer than the
    // geometry's grid (512 x 512 of 0.5 mm, 2 x 2 points averaged per pixel).
    const riner::Geometry g = riner::preset_geometry("fan2d-paper");
    const riner::Phantom phantom = riner::shepp_logan(g);
    riner::Geometry fine = g;
    fine.volume_shape = {512, 512};
    fine.voxel_mm = 0.5;
    const riner::Array raster = riner::rasterize(phantom, fine, 2);
    riner::Array projected(g.measurement_shape());
    projected.data = riner::ref::project(fine, raster.data);
    const double err = relative_rms(projected, riner::exact_projections(phantom, g));
    MESSAGE("fan2d-paper Shepp-Logan, 0.5 mm raster: relative RMS error " << err);
    CHECK(err < 0.01);
  }

  TEST_CASE("Joseph vs exact Shepp-Logan line integrals: cone beam converges with the grid") {
    // A cube grid over the cone3d-paper field of view, 8 views, coarse detector. Thin ellipsoid
    // shells make the raster error first order: halving the voxel must about halve the error.
    riner::Geometry g = riner::preset_geometry("cone3d-paper");
    g.n_u = 75;
    g.n_v = 75;
    g.pitch_u = g.pitch_v = 8.0;
    g.uniform_angles = riner::UniformAngles{8, 0.0, 2 * M_PI};
    g.angles = riner::uniform_angles(*g.uniform_angles);
    double errors[2];
    for (int level = 0; level < 2; ++level) {
      riner::Geometry grid = g;
      const std::size_t n = level == 0 ? 48 : 96;
      grid.volume_shape = {n, n, n};
      grid.voxel_mm = 256.0 / static_cast<double>(n);
      const riner::Phantom phantom = riner::shepp_logan(grid);
      const riner::Array raster = riner::rasterize(phantom, grid, 2);
      riner::Array projected(grid.measurement_shape());
      projected.data = riner::ref::project(grid, raster.data);
      errors[level] = relative_rms(projected, riner::exact_projections(phantom, grid));
      MESSAGE("cone Shepp-Logan on " << n << "^3: relative RMS error " << errors[level]);
    }
    CHECK(errors[1] < errors[0] / 1.7);
    CHECK(errors[1] < 0.07);
  }
}
