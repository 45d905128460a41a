#include <doctest/doctest.h>

#include "riner/error.hpp"
#include "riner/riner_config.hpp"

TEST_SUITE("riner_config") {
  TEST_CASE("defaults are valid and round-trip through JSON") {
    riner::RinerConfig c;
    CHECK_NOTHROW(c.validate());
    riner::RinerConfig d;
    d.training.steps = 1;
    d.update_from_json(c.to_json());
    CHECK(d.to_json() == c.to_json());
  }

  TEST_CASE("the paper preset holds the paper's values") {
    const riner::RinerConfig p = riner::RinerConfig::paper();
    CHECK(p.encoding.levels == 10);
    CHECK(p.encoding.log2_table_size == 10);
    CHECK(p.encoding.features == 8);
    CHECK(p.encoding.base_resolution == 2);
    CHECK(p.encoding.finest_resolution == 1024);
    CHECK(p.network.width == 128);
    CHECK(p.training.steps == 4000);
    CHECK(p.training.views_per_step * p.training.elements_per_step == 80);
    CHECK(p.training.learning_rate == 1e-3);
    CHECK(p.training.lr_decay_steps == 1000);
    CHECK(p.training.data_term == riner::DataTerm::kSum);
    CHECK_FALSE(p.rings.air_reference);  // riner's additions
    CHECK_FALSE(p.rings.gradient_reference);
    CHECK_FALSE(p.rings.response_reference);
    CHECK_NOTHROW(p.validate());
  }

  TEST_CASE("partial JSON updates and precise errors") {
    riner::RinerConfig c;
    c.update_from_json(
        R"({"network": {"width": 64}, "training": {"sampler": "mixed", "elements_per_step": 8}})");
    CHECK(c.network.width == 64);
    CHECK(c.training.sampler == riner::Sampler::kMixed);
    CHECK(c.encoding.levels == 8);  // untouched
    c.update_from_json(R"({"rings": {"air_reference": false, "air_erosion_px": 5}})");
    CHECK_FALSE(c.rings.air_reference);
    CHECK(c.rings.air.erosion_px == 5);
    CHECK(c.rings.air.air_fraction == riner::AirRingSettings{}.air_fraction);
    auto expect = [](const std::string& json, const std::string& message) {
      riner::RinerConfig cfg;
      try {
        cfg.update_from_json(json, "c.json");
        FAIL("accepted " << json);
      } catch (const riner::InputError& e) {
        CHECK(std::string(e.what()) == message);
      }
    };
    expect(R"({"training": {"stepz": 3}})", "c.json: config: unknown setting training.stepz");
    expect(R"({"network": {"width": 24}})",
           "config: network.width must be a multiple of 16 in 16..256");
    expect(R"({"training": {"steps": "many"}})",
           "c.json: config: training.steps must be an integer");
    expect(R"({"training": {"learning_rate": -1}})",
           "config: training.learning_rate must be in (0, 10)");
    expect(R"({"training": {"sampler": "random"}})",
           "c.json: config: training.sampler must be uniform, views-x-elements or mixed");
    expect(R"({"training": {"ring_lambda": 1}})",
           "config: training.ring_lambda needs the views-x-elements or mixed sampler with "
           "elements_per_step >= 3");
    expect(R"({"encoding": {"finest_resolution": 8}})",
           "config: encoding.finest_resolution must be 0 (the grid's size) or >= base_resolution "
           "and <= 2^20");
    expect(R"({"engine": "gpu"})", "c.json: engine must be opencl or reference (got \"gpu\")");
    expect("[1, 2]", "c.json: config: config must be an object");
    expect(R"({"rings": {"air_fraction": 1.5}})", "config: rings.air_fraction must be in (0, 1)");
    expect(R"({"rings": {"gradient_flat_fraction": 0}})",
           "config: rings.gradient_flat_fraction must be in (0, 1]");
    expect(R"({"rings": {"response_scale_px": 0}})",
           "config: rings.response_scale_px must be in (0, 1000]");
    expect(R"({"rings": {"air_reference": 1}})",
           "c.json: config: rings.air_reference must be true or false");
    expect(R"({"plan": {"kind": "fpga"}})", "config: plan.kind must be auto, cpu or gpu");
    expect(R"({"plan": {"float_atomics": "fast"}})",
           "config: plan.float_atomics must be auto, nvidia-ptx, cl_ext_float_atomics, "
           "amd-builtin or compare-exchange");
    expect(R"({"plan": {"kind": 1}})", "c.json: config: plan.kind must be a string");
    expect(R"({"plan": {"sample_group": -1}})",
           "config: plan.sample_group must be in 0..4096 (0: the device's choice)");
    expect(R"({"plan": {"lanes": 4}})", "c.json: config: unknown setting plan.lanes");
    expect(R"({"training": {"air_margin_px": 100}})",
           "config: training.air_margin_px must be in 0..64");
    expect(R"({"training": {"air_noise_sigmas": 0}})",
           "config: training.air_noise_sigmas must be in [0.5, 100]");
    expect(R"({"training": {"rays_per_step": -3}})",
           "config: training.rays_per_step must be in 1..2^20, or 0 (the device's execution "
           "plan chooses)");
  }

  TEST_CASE("the execution plan and air skipping are settings like the others") {
    riner::RinerConfig c;
    CHECK(c.plan.kind == "auto");
    CHECK(c.training.rays_per_step == 0);  // the plan's choice
    CHECK(c.training.skip_air);
    CHECK_FALSE(riner::RinerConfig::paper().training.skip_air);
    c.update_from_json(
        R"({"plan": {"kind": "gpu", "float_atomics": "compare-exchange", "sample_group": 32,
                     "gradient_slices": 7, "grid_bands": 2},
            "training": {"skip_air": false, "air_margin_px": 2, "air_noise_sigmas": 6}})");
    CHECK(c.plan.kind == "gpu");
    CHECK(c.plan.float_atomics == "compare-exchange");
    CHECK(c.plan.sample_group == 32);
    CHECK(c.plan.gradient_slices == 7);
    CHECK(c.plan.grid_bands == 2);
    CHECK_FALSE(c.training.skip_air);
    CHECK(c.training.air_margin_px == 2);
    CHECK(c.training.air_noise_sigmas == 6.0);
    riner::RinerConfig d;
    d.update_from_json(c.to_json());
    CHECK(d.to_json() == c.to_json());
  }
}
