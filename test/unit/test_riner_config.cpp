#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "riner/error.hpp"
#include "riner/riner_config.hpp"
#include "rings/ring_settings.hpp"
#include "settings/config_settings.hpp"

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
    expect(R"({"training": {"stepz": 3}})", "c.json: unknown setting training.stepz");
    expect(R"({"network": {"width": 24}})", "c.json: network.width must be a multiple of 16");
    expect(R"({"training": {"steps": "many"}})", "c.json: training.steps must be an integer");
    expect(R"({"training": {"steps": 3.5}})",
           "c.json: training.steps must be an integer (got 3.5)");
    expect(R"({"training": {"seed": 1180591620717411303424}})",
           "c.json: training.seed must be an integer (got 1.1805916207174113e+21, beyond "
           "64 bits)");
    // 1e19 written as a float fits 64 bits (the seed's range is 0..2^64 - 1): only a float.
    expect(R"({"training": {"seed": 1e19}})",
           "c.json: training.seed must be an integer (got 1e+19)");
    expect(R"({"training": {"learning_rate": -1}})",
           "c.json: training.learning_rate must be in (0, 10) (Adam's learning rate)");
    expect(R"({"training": {"sampler": "random"}})",
           "c.json: training.sampler must be one of uniform, views-x-elements, mixed, even");
    expect(R"({"training": {"ring_lambda": 1}})",
           "c.json: training.ring_lambda needs the views-x-elements or mixed sampler "
           "with elements_per_step >= 3");
    expect(R"({"encoding": {"finest_resolution": 8}})",
           "c.json: encoding.finest_resolution must be 0 (the grid's size) or >= "
           "base_resolution");
    expect(R"({"engine": "gpu"})", "c.json: engine must be one of opencl, reference");
    expect("[1, 2]", "c.json: the settings must be a JSON object");
    expect(R"({"rings": {"gradient_flat_fraction": 0}})",
           "c.json: rings.gradient_flat_fraction must be in (0, 1] (gradient correction: "
           "fraction of each circle's flattest points in the median)");
    expect(R"({"rings": {"air_reference": 1}})",
           "c.json: rings.air_reference must be true or false");
    expect(R"({"plan": {"kind": 1}})", "c.json: plan.kind must be a string: one of auto, cpu, gpu");
    expect(R"({"plan": {"lanes": 4}})", "c.json: unknown setting plan.lanes");
    expect(R"({"plan": 4})", "c.json: plan must be an object");
    expect(R"({"training": {"rays_per_step": -3}})",
           "c.json: training.rays_per_step must be in 0..1048576 (uniform, even and "
           "mixed samplers' rays per step; 0: the execution plan's)");
    // A value beyond an int's range is refused, not wrapped.
    expect(R"({"training": {"steps": 5000000000}})",
           "c.json: training.steps must be in -1..10000000 (training steps; -1: the scan's, "
           "24000 in 2D and 12000 in 3D or more (min_draws_per_ray, min_samples_per_voxel))");
    expect(R"({"training": {"seed": -1}})",
           "c.json: training.seed must be in 0..1.84467e+19 (seed of the initial "
           "weights and the sampler)");
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

// Every setting of the table: a value other than the default round-trips through config.json
// and through set(); each finite bound is enforced (just outside it is refused naming the
// setting, the bound itself accepted where the range is closed); a value of the wrong type is
// refused.
TEST_SUITE("settings table") {
  using riner::RinerConfig;
  using riner::settings::Type;

  // A value just outside `bound` (below when `below`): the next integer, or a relative step.
  double outside(Type type, double bound, bool open, bool below) {
    const double sign = below ? -1.0 : 1.0;
    if (open) return bound;
    if (type == Type::kInteger) return bound + sign;
    return bound + sign * std::max(1e-6, std::fabs(bound) * 1e-3);
  }

  std::string set_json(const riner::settings::Setting<RinerConfig>& s, const std::string& value) {
    if (s.section.empty()) return "{\"" + s.key + "\": " + value + "}";
    return "{\"" + s.section + "\": {\"" + s.key + "\": " + value + "}}";
  }

  std::string number_text(Type type, double v) {
    char text[64];
    std::snprintf(text, sizeof(text), type == Type::kInteger ? "%.0f" : "%.17g", v);
    return text;
  }

  TEST_CASE("every setting round-trips and every bound is enforced") {
    const auto& table = riner::config_settings();
    CHECK(table.size() == RinerConfig::settings().size());
    // ring_lambda > 0 needs this sampler; everything else is valid on the defaults.
    const std::string base = R"({"training": {"sampler": "mixed", "elements_per_step": 4}})";
    for (const auto& s : table) {
      CAPTURE(s.name());
      RinerConfig defaults;
      defaults.update_from_json(base);
      const nlohmann::json default_value = s.get(defaults);
      std::vector<std::string> candidates;
      if (s.type == Type::kBool) candidates = {default_value.get<bool>() ? "false" : "true"};
      if (s.type == Type::kChoice) {
        for (const auto& c : s.choices) candidates.push_back("\"" + c + "\"");
      }
      if (s.type == Type::kInteger || s.type == Type::kNumber) {
        const riner::settings::Range& r = s.range;
        REQUIRE(std::isfinite(r.lo));
        REQUIRE(std::isfinite(r.hi));
        const double mid =
            s.type == Type::kInteger ? std::floor(0.5 * (r.lo + r.hi)) : 0.5 * (r.lo + r.hi);
        if (!r.lo_open) candidates.push_back(number_text(s.type, r.lo));
        if (!r.hi_open && r.hi < 1e15) candidates.push_back(number_text(s.type, r.hi));
        candidates.push_back(number_text(s.type, mid));
        // Out of range, below and above: refused, naming the setting.
        for (bool below : {true, false}) {
          const double bad =
              outside(s.type, below ? r.lo : r.hi, below ? r.lo_open : r.hi_open, below);
          if (std::fabs(bad) > 1e15) continue;
          RinerConfig c = defaults;
          try {
            c.update_from_json(set_json(s, number_text(s.type, bad)), "t.json");
            FAIL("accepted " << bad);
          } catch (const riner::InputError& e) {
            CHECK(std::string(e.what()).find(s.name() + " must be") != std::string::npos);
          }
        }
        RinerConfig c = defaults;
        CHECK_THROWS_AS(c.update_from_json(set_json(s, "\"text\"")), riner::InputError);
      } else {
        RinerConfig c = defaults;
        CHECK_THROWS_AS(c.update_from_json(set_json(s, "17.5")), riner::InputError);
      }
      // The first candidate other than the default that the cross-setting rules allow.
      bool round_tripped = false;
      for (const std::string& text : candidates) {
        if (nlohmann::json::parse(text) == default_value) continue;
        RinerConfig c = defaults;
        try {
          c.update_from_json(set_json(s, text));
        } catch (const riner::InputError&) {
          continue;  // e.g. network.width 136, not a multiple of 16
        }
        CHECK(s.get(c) == nlohmann::json::parse(text));
        RinerConfig d;
        d.update_from_json(c.to_json());
        CHECK(d.to_json() == c.to_json());
        RinerConfig e = defaults;
        e.set(s.name(), text);
        CHECK(e.to_json() == c.to_json());
        round_tripped = true;
        break;
      }
      CHECK(round_tripped);
    }
  }

  TEST_CASE("set() takes bare words for choices and names unknown settings") {
    RinerConfig c;
    c.set("training.sampler", "views-x-elements");
    CHECK(c.training.sampler == riner::Sampler::kViewsTimesElements);
    c.set("engine", "reference");
    CHECK(c.engine == riner::Engine::kReference);
    c.set("rings.response_air_fraction", "0.05");
    CHECK(c.rings.response.air_fraction == 0.05);
    CHECK_THROWS_WITH_AS(c.set("training.stepz", "3"),
                         "config: unknown setting training.stepz (riner settings lists them)",
                         riner::InputError);
    CHECK_THROWS_WITH_AS(c.set("network.width", "24"),
                         "config: network.width must be a multiple of 16", riner::InputError);
    CHECK(c.network.width == 32);  // a refused change leaves the config as it was
  }

  TEST_CASE("the corrections refuse settings outside the config's bounds") {
    riner::AirRingSettings air;
    air.erosion_px = 65;
    CHECK_THROWS_WITH_AS(riner::rings::validate("air ring correction", air),
                         "air ring correction: rings.air_erosion_px must be in 0..64 (air pixels "
                         "this far (|dx|+|dy|) from anything that is not air)",
                         riner::InputError);
    riner::ResponseRingSettings response;
    response.max_mean_response_change = 11;
    CHECK_THROWS_AS(riner::rings::validate("r", response), riner::InputError);
  }
}
