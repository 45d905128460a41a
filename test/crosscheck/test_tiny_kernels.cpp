// Every kernel on tiny inputs: fast enough to run under oclgrind (ctest label "oclgrind"),
// which reports out-of-bounds accesses, races and uninitialised reads.
#include <doctest/doctest.h>

#include <random>

#include "riner/fbp.hpp"
#include "riner/projector.hpp"
#include "riner/reconstructor.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"
#include "support/geometries.hpp"
#include "support/tiny_problem.hpp"
#include "support/tolerances.hpp"

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
      CHECK(riner::test::compare(device.project(x).data, reference.project(x).data).rms_rel <
            riner::test::tolerance::kChained);
      CHECK(riner::test::compare(device.adjoint(y).data, reference.adjoint(y).data).rms_rel <
            riner::test::tolerance::kChained);
      riner::FbpOptions options;
      options.device = riner::test::device();
      const riner::Scan scan{y, g, 0};
      const riner::Array fbp_device = riner::fbp(scan, options);
      options.engine = riner::Engine::kReference;
      CHECK(riner::test::compare(fbp_device.data, riner::fbp(scan, options).data).rms_rel <
            riner::test::tolerance::kChained);
    }
  }

  TEST_CASE(
      "Riner's training kernels under both execution plans on a tiny problem (mixed batches, "
      "ring prior, coarse to fine)") {
    riner::test::TinyProblem t = riner::test::tiny_problem(3);
    riner::RinerConfig c = riner::test::tiny_config();
    c.encoding = {3, 2, 8, 4, 16};
    c.training.sampler = riner::Sampler::kMixed;
    c.training.rays_per_step = 6;
    c.training.views_per_step = 2;
    c.training.elements_per_step = 4;
    c.training.ring_lambda = 1.0;
    c.training.level_warmup_steps = 1;
    c.training.jitter = true;
    riner::RinerConfig r = c;
    r.engine = riner::Engine::kReference;
    riner::Reconstructor reference(t.scan, r);
    reference.step(3);
    const auto b = reference.history();
    const riner::Array image = reference.image();
    for (const char* kind : {"cpu", "gpu"}) {
      CAPTURE(kind);
      c.plan.kind = kind;
      c.plan.sample_group = 4;  // several work-groups even on this tiny batch
      c.plan.gradient_slices = 3;
      riner::Reconstructor device(t.scan, c, riner::test::device());
      device.step(3);
      const auto a = device.history();
      for (std::size_t i = 0; i < 3; ++i)
        CHECK(a[i].data_loss ==
              doctest::Approx(b[i].data_loss).epsilon(riner::test::tolerance::kTraining));
      CHECK(riner::test::compare(device.image().data, image.data).rms_rel <
            riner::test::tolerance::kTraining);
    }
  }
}
