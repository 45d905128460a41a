// Partial rings (training.partial_responses): the evidence that an element's response changes
// or dies part-way (model/response_changes.hpp) finds each simulated change at its view and
// nothing on the unchanged twin, and the response map (model/response_map.hpp) gives every
// reading its segment's slot; the TrainingSetup sizes alpha and beta by those slots.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "model/response_changes.hpp"
#include "model/response_map.hpp"
#include "model/starved_readings.hpp"
#include "support/geometries.hpp"
#include "support/partial_scan.hpp"
#include "training/trainer.hpp"

namespace {

using riner::test::partial_scan;
using riner::test::PartialScan;

// As training looks: after the +inf readings that are no bound became NaN (a dying element's
// dark readings; model/starved_readings.hpp).
std::vector<riner::model::ResponseChange> changes_in(riner::Array rho) {
  riner::model::mark_starved_readings(rho, rho.shape[0]);
  return riner::model::find_response_changes(rho, {});
}

// A training setup's settings on the reference engine, the whole grid sampled.
riner::RinerConfig setup_config() {
  riner::RinerConfig c;
  c.engine = riner::Engine::kReference;
  c.training.skip_air = false;
  return c;
}

}  // namespace

TEST_SUITE("response changes") {
  TEST_CASE("the response map gives each reading its segment's slot") {
    const riner::model::ResponseMap map(10, 8, {{2, {3}, false}, {7, {2, 5}, true}});
    CHECK(map.varies());
    CHECK(map.slots() == 13);
    CHECK(map.slot(0, 7) == 0);
    CHECK(map.slot(2, 2) == 2);
    CHECK(map.slot(2, 3) == 10);
    CHECK(map.slot(7, 1) == 7);
    CHECK(map.slot(7, 2) == 11);
    CHECK(map.slot(7, 5) == 12);
    CHECK(map.element_of(12) == 7);
    CHECK(map.element_of(10) == 2);
    const auto segments = map.segments(7);
    REQUIRE(segments.size() == 3);
    CHECK(segments[1].first_view == 2);
    CHECK(segments[1].views == 3);
    CHECK(segments[2].views == 3);
    CHECK_FALSE(riner::model::ResponseMap(10).varies());
  }

  TEST_CASE("every simulated change is found at its view, and dying part-way by its readings") {
    // Seed 6: no change hides behind an edge of the phantom (seeds 4, 5, 7, 8 miss 0-2 of 7
    // there, and none finds a change that is not).
    const PartialScan s = partial_scan(5, 2, 6);
    const auto found = changes_in(s.scan.measurement);
    std::size_t changing = 0;
    for (std::size_t e = 0; e < s.alpha.shape[1]; ++e) {
      const std::vector<std::size_t> truth =
          riner::response_change_views(s.alpha, s.scan.geometry, e);
      if (truth.empty()) continue;
      ++changing;
      CAPTURE(e);
      const auto it =
          std::find_if(found.begin(), found.end(), [&](const auto& c) { return c.element == e; });
      REQUIRE(it != found.end());
      REQUIRE(it->starts.size() == 1);
      CHECK(it->starts[0] == truth[0]);
      CHECK(it->dies == (s.alpha.data[(s.alpha.shape[0] - 1) * s.alpha.shape[1] + e] == 0.0f));
    }
    CHECK(changing == 7);
    CHECK(found.size() == changing);  // and nothing else
  }

  TEST_CASE("changes near the scan's ends are found, with the views left to hold them") {
    // 240 views: changes 12, 20 and 30 views from either end (the hold's window is 24 views in
    // mid-scan: before, changes within 24 views of an end were not looked for), each element's
    // response stepping by 20-30%, inside the object and in the air beside it. (Where an edge of
    // the phantom crosses the element within the step's window, as it does for elements 30 and
    // 60 near view 26, the step is not told from the object, at any view.)
    riner::test::PartialScan s = partial_scan(0, 0, 6);
    const riner::Geometry& g = s.scan.geometry;
    const std::size_t views = g.n_views();
    const std::size_t elements = g.n_u;
    riner::RingModel model;
    model.seed = 6;
    const riner::Array base = riner::draw_responses(g, model);
    riner::Array alpha({views, elements});
    for (std::size_t v = 0; v < views; ++v) {
      std::copy_n(base.data.begin(), elements, alpha.data.begin() + v * elements);
    }
    const std::vector<std::pair<std::size_t, std::size_t>> changes{
        {20, 12}, {45, 20}, {110, 30}, {75, views - 30}, {90, views - 20}, {100, views - 12}};
    for (std::size_t i = 0; i < changes.size(); ++i) {
      const auto [e, from] = changes[i];
      const float factor = (i % 2 == 0) ? 1.3f : 0.8f;
      for (std::size_t v = from; v < views; ++v) alpha.data[v * elements + e] *= factor;
    }
    const riner::Array clean = riner::exact_projections(riner::shepp_logan(g, 0.1), g);
    const riner::Array rho = riner::corrupt_measurement(clean, alpha, model);
    const auto found = changes_in(rho);
    for (const auto& [e, from] : changes) {
      CAPTURE(e);
      const auto it =
          std::find_if(found.begin(), found.end(), [&](const auto& c) { return c.element == e; });
      REQUIRE(it != found.end());
      CHECK(it->starts == std::vector<std::size_t>{from});
    }
    CHECK(found.size() == changes.size());  // and nothing else
  }

  TEST_CASE("the unchanged twin and a clean scan show no change") {
    for (std::uint64_t seed : {4, 5, 6, 7, 8}) {
      CAPTURE(seed);
      CHECK(changes_in(partial_scan(0, 0, seed).scan.measurement).empty());
    }
    riner::Scan clean = partial_scan(0, 0, 4).scan;
    const riner::Array exact =
        riner::exact_projections(riner::shepp_logan(clean.geometry, 0.1), clean.geometry);
    CHECK(changes_in(exact).empty());
  }

  TEST_CASE("3D: each detector row's changes, at their views, as pixels of the detector") {
    const riner::Geometry g = riner::test::make_geometry(riner::GeometryType::kParallel3d, 240, 96,
                                                         6, {6, 64, 64}, 1.0, 1.0, M_PI);
    const riner::Array clean = riner::exact_projections(riner::shepp_logan(g, 0.1), g);
    riner::RingModel model;
    model.seed = 3;
    model.partial_elements = 8;
    model.partial_dead_elements = 2;
    const riner::Array alpha = riner::draw_responses(g, model);
    REQUIRE(alpha.shape == std::vector<std::size_t>{240, 6, 96});
    const riner::Array rho = riner::corrupt_measurement(clean, alpha, model);
    const auto found = changes_in(rho);
    std::size_t changing = 0, at_their_view = 0;
    for (std::size_t e = 0; e < 6 * 96; ++e) {
      const std::vector<std::size_t> truth = riner::response_change_views(alpha, g, e);
      const auto it =
          std::find_if(found.begin(), found.end(), [&](const auto& c) { return c.element == e; });
      CAPTURE(e);
      if (truth.empty()) {
        CHECK(it == found.end());  // nothing found that did not change
        continue;
      }
      ++changing;
      at_their_view += it != found.end() && it->starts == truth;
    }
    MESSAGE(at_their_view << " of " << changing << " changing pixels found at their view");
    CHECK(changing == 10);
    CHECK(at_their_view >= 9);
  }

  TEST_CASE("training gives each changing element a slot per segment, off by the setting") {
    const PartialScan s = partial_scan(3, 1, 6);
    riner::RinerConfig c = setup_config();
    const riner::detail::TrainingSetup on(s.scan, c);
    CHECK(on.responses.slots() == 128 + 4);
    CHECK(on.layout.elements == 128 + 4);
    CHECK(on.invalid_readings.size() == 128 + 4);
    c.training.partial_responses = false;
    const riner::detail::TrainingSetup off(s.scan, c);
    CHECK(off.layout.elements == 128);
    CHECK_FALSE(off.responses.varies());
  }

  TEST_CASE("the slots that read nothing start with beta near 0: dead, and a dying one's end") {
    // Two dead elements (+inf in every view) and one dying part-way: its segment after it died
    // reads nothing either. At the paper's beta0 = 1 their readings, counted as 0, pulled the
    // field down along their rays; every other slot starts there.
    const PartialScan s = partial_scan(0, 1, 6);
    const riner::detail::TrainingSetup setup(s.scan, setup_config());
    REQUIRE(setup.responses.slots() == 128 + 1);
    std::vector<std::size_t> dead;
    for (std::size_t e = 0; e < 128; ++e) {
      if (s.alpha(0, e) == 0.0f) dead.push_back(e);
    }
    REQUIRE(dead.size() == 2);
    dead.push_back(128);  // the dying element's last segment
    CHECK(setup.unread_slots == dead);
    const std::vector<float> p = setup.initial_parameters();
    for (std::size_t slot = 0; slot < setup.responses.slots(); ++slot) {
      const bool unread = std::find(dead.begin(), dead.end(), slot) != dead.end();
      CHECK(p[setup.layout.beta_offset + slot] ==
            (unread ? riner::TrainingConfig{}.unread_beta0 : 1.0f));
    }
  }
}
