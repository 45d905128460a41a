// The evidence that picks alpha's row x column factors (model/factor_evidence.hpp, training
// alpha_model auto): a cone-beam Shepp-Logan through a factored detector reads close to 1,
// through independent pixels close to 1/rows + 1/columns; dead pixels drop out; a 2D scan
// has none; the Reconstructor trains factors only on that evidence or when asked.
#include <doctest/doctest.h>

#include "model/factor_evidence.hpp"
#include "riner/phantom.hpp"
#include "riner/simulate.hpp"
#include "support/geometries.hpp"
#include "training/trainer.hpp"

namespace {

riner::Scan ring_scan(riner::ResponsePattern pattern, std::size_t dead_columns = 0) {
  const riner::Geometry g = riner::test::small_cone3d();  // 37 x 61 detector, 40 views
  const riner::Array clean = riner::exact_projections(riner::shepp_logan(g, 0.1), g);
  riner::RingModel model;
  model.seed = 5;
  model.pattern = pattern;
  model.dead_columns = dead_columns;
  const riner::Array alpha = riner::draw_responses(g, model);
  return riner::Scan{riner::corrupt_measurement(clean, alpha, model), g, 0};
}

}  // namespace

TEST_SUITE("factor evidence") {
  TEST_CASE("a factored detector reads near 1, independent pixels near 0") {
    const auto factored =
        riner::model::factor_evidence(ring_scan(riner::ResponsePattern::kRowsTimesColumns));
    const auto pixels =
        riner::model::factor_evidence(ring_scan(riner::ResponsePattern::kPerElement));
    MESSAGE("factored " << factored.explained << ", per pixel " << pixels.explained);
    CHECK(factored.pixels > 3000);
    CHECK(factored.explained > 0.9);
    CHECK(pixels.explained < 0.2);
  }

  TEST_CASE("dead columns drop out instead of deciding") {
    const auto e =
        riner::model::factor_evidence(ring_scan(riner::ResponsePattern::kRowsTimesColumns, 3));
    CHECK(e.explained > 0.9);
  }

  TEST_CASE("a 2D scan has no evidence and keeps alpha per element, even when asked") {
    riner::Scan scan;
    scan.geometry = riner::test::small_fan2d();
    scan.measurement = riner::Array(scan.geometry.measurement_shape(), 0.5f);
    CHECK(riner::model::factor_evidence(scan).pixels == 0);
    riner::RinerConfig c;
    c.training.alpha_model = riner::AlphaModel::kRowsTimesColumns;
    c.training.skip_air = false;
    const riner::detail::TrainingSetup setup(scan, c);
    CHECK(setup.alpha_model == riner::AlphaModel::kPerElement);
    CHECK_FALSE(setup.layout.factored_alpha());
  }

  TEST_CASE("the setup trains factors by the evidence or when asked, never otherwise") {
    riner::RinerConfig c;
    c.training.skip_air = false;
    const riner::Scan factored = ring_scan(riner::ResponsePattern::kRowsTimesColumns);
    const riner::Scan pixels = ring_scan(riner::ResponsePattern::kPerElement);
    CHECK(riner::detail::TrainingSetup(factored, c).layout.factored_alpha());
    CHECK_FALSE(riner::detail::TrainingSetup(pixels, c).layout.factored_alpha());
    c.training.alpha_model = riner::AlphaModel::kPerElement;
    CHECK_FALSE(riner::detail::TrainingSetup(factored, c).layout.factored_alpha());
    c.training.alpha_model = riner::AlphaModel::kRowsTimesColumns;
    const riner::detail::TrainingSetup forced(pixels, c);
    CHECK(forced.layout.factored_alpha());
    CHECK(forced.layout.factor_rows == 37);
    CHECK(forced.layout.factor_columns == 61);
  }
}
