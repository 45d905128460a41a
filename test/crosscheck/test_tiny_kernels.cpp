// Every kernel on tiny inputs: fast enough to run under oclgrind (ctest label "oclgrind"),
// which reports out-of-bounds accesses, races and uninitialised reads.
#include <doctest/doctest.h>

#include <random>

#include "riner/fbp.hpp"
#include "riner/projector.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"
#include "support/geometries.hpp"

TEST_SUITE("tiny_kernels") {
  TEST_CASE("projector, adjoint and FBP on tiny geometries of every type") {
    using riner::GeometryType;
    const riner::Geometry geometries[] = {
        riner::test::make_geometry(GeometryType::kFan2d, 5, 11, 1, {7, 9}, 1.5, 1.0),
        riner::test::make_geometry(GeometryType::kParallel2d, 4, 10, 1, {8, 8}, 1.0, 1.0, M_PI),
        riner::test::make_geometry(GeometryType::kCone3d, 3, 9, 7, {5, 6, 7}, 1.5, 1.0),
        riner::test::make_geometry(GeometryType::kParallel3d, 3, 8, 5, {4, 6, 6}, 1.0, 1.0, M_PI)};
    std::mt19937 rng(static_cast<unsigned>(riner::test::seed()));
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (const riner::Geometry& g : geometries) {
      CAPTURE(std::string(riner::geometry_type_name(g.type)));
      riner::Array x(g.volume_shape);
      for (float& v : x.data) v = u(rng);
      riner::Array y(g.measurement_shape());
      for (float& v : y.data) v = u(rng);
      const riner::Projector device(g, riner::Engine::kOpenCL, riner::test::device());
      const riner::Projector reference(g, riner::Engine::kReference);
      CHECK(riner::test::compare(device.project(x).data, reference.project(x).data).rms_rel < 1e-4);
      CHECK(riner::test::compare(device.adjoint(y).data, reference.adjoint(y).data).rms_rel < 1e-4);
      riner::FbpOptions options;
      options.device = riner::test::device();
      const riner::Scan scan{y, g, 0};
      const riner::Array fbp_device = riner::fbp(scan, options);
      options.engine = riner::Engine::kReference;
      CHECK(riner::test::compare(fbp_device.data, riner::fbp(scan, options).data).rms_rel < 1e-4);
    }
  }
}
