// The residual detail on the OpenCL device against the reference engine (its projector and FBP
// are each cross-checked; this checks the whole step on both).
#include <doctest/doctest.h>

#include <cmath>

#include "riner/phantom.hpp"
#include "riner/projector.hpp"
#include "riner/residual_detail.hpp"
#include "riner/simulate.hpp"
#include "support/fixture.hpp"
#include "support/geometries.hpp"

TEST_SUITE("residual detail") {
  TEST_CASE("OpenCL and reference give the same detail back") {
    for (const riner::Geometry& g : {riner::test::small_fan2d(), riner::test::small_cone3d()}) {
      CAPTURE(std::string(riner::geometry_type_name(g.type)));
      const riner::Array truth = riner::rasterize(riner::shepp_logan(g), g);
      riner::RingModel model;
      model.photons = 0.0;
      model.seed = 2;
      const riner::SimulatedScan sim =
          riner::simulate(truth, riner::Projector(g, riner::Engine::kReference), model);
      riner::Array log_alpha = sim.alpha;
      std::vector<std::size_t> dead;
      for (std::size_t e = 0; e < log_alpha.size(); ++e) {
        if (log_alpha.data[e] == 0.0f) dead.push_back(e);
        log_alpha.data[e] = std::log(std::max(log_alpha.data[e], 1e-8f));
      }
      // A field that lacks the phantom's fine structure: half its values.
      riner::Array field = truth;
      for (float& v : field.data) v *= 0.5f;
      const riner::ResidualDetailResult ref = riner::return_residual_detail(
          field, field, sim.scan, log_alpha, dead, {}, {}, riner::Engine::kReference);
      const riner::ResidualDetailResult dev =
          riner::return_residual_detail(field, field, sim.scan, log_alpha, dead, {}, {},
                                        riner::Engine::kOpenCL, riner::test::device());
      REQUIRE(ref.report.applied);
      REQUIRE(dev.report.applied);
      CHECK(dev.report.consistent_share ==
            doctest::Approx(ref.report.consistent_share).epsilon(1e-3));
      double largest = 0.0, diff = 0.0;
      for (std::size_t p = 0; p < truth.size(); ++p) {
        largest = std::max(largest, std::fabs(double(ref.image.data[p])));
        diff = std::max(diff, std::fabs(double(dev.image.data[p]) - ref.image.data[p]));
      }
      // Float FBP on the device against the double reference: measured 2.2e-6 (fan) and 1.5e-6
      // (cone) of the largest value.
      CHECK(diff <= 1e-4 * largest);
    }
  }
}
