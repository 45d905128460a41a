// kernels/project.cl and kernels/backproject.cl against the reference projector.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "riner/error.hpp"
#include "riner/projector.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"
#include "support/geometries.hpp"
#include "support/tolerances.hpp"

namespace {

riner::Array random_array(std::vector<std::size_t> shape, std::uint64_t salt) {
  std::mt19937_64 rng(riner::test::seed() + salt);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  riner::Array a(std::move(shape));
  for (float& v : a.data) v = u(rng);
  return a;
}

double inner(const riner::Array& a, const riner::Array& b) {
  double s = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) s += static_cast<double>(a.data[i]) * b.data[i];
  return s;
}

// Views from exactly 0 over half a turn: view 15 lies at 90 degrees, where the rotation's cos
// is 6e-17 and a ray that misses the grid has plane bounds near 1e17, which no int holds (the
// kernels once looped over ~2^31 planes there).
riner::Geometry axis_aligned(riner::Geometry g) {
  g.uniform_angles = riner::UniformAngles{30, 0.0, M_PI};
  g.angles = riner::uniform_angles(*g.uniform_angles);
  return g;
}

// A cone beam's grid above the source's plane, as a slab's: the rays move, not the grid.
riner::Geometry raised(riner::Geometry g) {
  g.grid_centre_z_mm = 3.5 * g.voxel_mm;
  return g;
}

const riner::Geometry kGeometries[] = {riner::test::small_fan2d(),
                                       riner::test::small_parallel2d(),
                                       riner::test::small_cone3d(),
                                       raised(riner::test::small_cone3d()),
                                       riner::test::small_parallel3d(),
                                       axis_aligned(riner::test::small_parallel2d()),
                                       axis_aligned(riner::test::small_parallel3d())};

}  // namespace

TEST_SUITE("projector") {
  TEST_CASE("OpenCL forward and adjoint match the reference") {
    for (const riner::Geometry& g : kGeometries) {
      CAPTURE(std::string(riner::geometry_type_name(g.type)));
      const riner::Projector device(g, riner::Engine::kOpenCL, riner::test::device());
      const riner::Projector reference(g, riner::Engine::kReference);
      const riner::Array x = random_array(g.volume_shape, 3);
      const riner::Array y = random_array(g.measurement_shape(), 4);
      // fp32 accumulation over a few hundred samples per ray: ~1e-6 relative; 1e-4 leaves room
      // for devices without fused multiply-add.
      const auto forward = riner::test::compare(device.project(x).data, reference.project(x).data);
      CHECK_MESSAGE(forward.rms_rel < riner::test::tolerance::kChained, forward.describe());
      const auto adjoint = riner::test::compare(device.adjoint(y).data, reference.adjoint(y).data);
      CHECK_MESSAGE(adjoint.rms_rel < riner::test::tolerance::kChained, adjoint.describe());
    }
  }

  TEST_CASE("OpenCL adjoint property holds in fp32") {
    for (const riner::Geometry& g : kGeometries) {
      CAPTURE(std::string(riner::geometry_type_name(g.type)));
      const riner::Projector p(g, riner::Engine::kOpenCL, riner::test::device());
      const riner::Array x = random_array(g.volume_shape, 5);
      const riner::Array y = random_array(g.measurement_shape(), 6);
      const double ax_y = inner(p.project(x), y);
      const double x_aty = inner(x, p.adjoint(y));
      CHECK(std::fabs(ax_y - x_aty) <= riner::test::tolerance::kChained * std::fabs(ax_y));
    }
  }

  TEST_CASE("forward projection is bit-identical across repeats") {
    const riner::Geometry g = riner::test::small_cone3d();
    const riner::Projector p(g, riner::Engine::kOpenCL, riner::test::device());
    const riner::Array x = random_array(g.volume_shape, 7);
    const riner::Array first = p.project(x);
    for (int i = 0; i < 5; ++i) CHECK(p.project(x).data == first.data);
  }

  TEST_CASE("shape mismatches are InputErrors") {
    const riner::Geometry g = riner::test::small_fan2d();
    const riner::Projector p(g, riner::Engine::kReference);
    CHECK_THROWS_AS(p.project(riner::Array({3, 3})), riner::InputError);
    CHECK_THROWS_AS(p.adjoint(riner::Array({3, 3})), riner::InputError);
  }
}
