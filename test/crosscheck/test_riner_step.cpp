// The training step of each execution plan (kernels/riner_step.cl with mlp_gradient.cl and
// hash_grid_gradient.cl, ops::RinerStepOp) against its CPU twin ref::riner_step, in double, on
// random parameters, measurements and batches: ray sums, their loss gradients, every
// parameter's gradient, the losses. The cpu plan runs both shapes of its per-sample kernels
// (riner_step_lanes.cl and one sample per work-item), which must agree to the bit.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <string>

#include "cl/buffer.hpp"
#include "cl/device_access.hpp"
#include "model/batch_sampler.hpp"
#include "model/packed_batch.hpp"
#include "model/parameter_layout.hpp"
#include "model/ray_segments.hpp"
#include "ops/riner_step.hpp"
#include "reference/riner_step_ref.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"
#include "support/geometries.hpp"
#include "support/tolerances.hpp"

namespace {

riner::cl::Context& ctx() { return riner::cl::context_of(riner::test::device()); }

struct Scenario {
  const char* name;
  riner::Geometry geometry;
  riner::Sampler sampler = riner::Sampler::kUniform;
  bool jitter = false;
  double ring_lambda = 0.0;
  double relative_beta_threshold = 0.0;
  bool hold_valid_beta = false;
  bool coarse_to_fine = false;
  int hidden_layers = 1;
  int features = 2;  // 2: the dense levels' paired loads; else corner by corner
  int width = 16;
  bool changing_responses = false;  // a few elements' responses change or die part-way
  int rays_per_step = 40;
};

std::vector<Scenario> scenarios() {
  std::vector<Scenario> s;
  Scenario fan{"fan 2D, uniform rays, midpoints, 3 features", riner::test::small_fan2d()};
  fan.features = 3;
  s.push_back(fan);
  Scenario mixed{
      "parallel 2D, mixed batch, ring prior, jitter, coarse to fine, relative beta, 2 hidden "
      "layers",
      riner::test::small_parallel2d()};
  mixed.sampler = riner::Sampler::kMixed;
  mixed.jitter = true;
  mixed.ring_lambda = 3.0;
  mixed.relative_beta_threshold = 4.0;
  mixed.hold_valid_beta = true;
  mixed.coarse_to_fine = true;
  mixed.hidden_layers = 2;
  s.push_back(mixed);
  // A 32^2 grid read by 61 elements: short rays, and few elements for the rays to cover, since
  // oclgrind interprets every sample (ctest oclgrind_response_slots).
  Scenario changing{
      "fan 2D, responses changing and dying part-way, relative beta, beta held",
      riner::test::make_geometry(riner::GeometryType::kFan2d, 90, 61, 1, {32, 32}, 1.5, 1.0)};
  changing.changing_responses = true;
  changing.relative_beta_threshold = 4.0;
  changing.hold_valid_beta = true;
  changing.rays_per_step = 300;  // ~5 rays per element: every segment of 40, 45 and 50 is read
  s.push_back(changing);
  Scenario cone{"cone 3D, uniform rays, jitter, hashed levels, width 32",
                riner::test::small_cone3d()};
  cone.jitter = true;
  cone.width = 32;
  s.push_back(cone);
  return s;
}

// A step's fixed inputs on the device, and its loss history.
struct DeviceInputs {
  riner::cl::Buffer<cl_uint> invalid;
  riner::cl::Buffer<cl_uint> responses;
  riner::cl::Buffer<float> params;
  riner::cl::Buffer<float> history;

  DeviceInputs(const std::vector<std::uint32_t>& inv, const std::vector<float>& p,
               const riner::model::ResponseMap& map)
      : invalid(ctx(), std::span<const cl_uint>(inv)),
        responses(ctx(), std::span<const cl_uint>(map.table())),
        params(ctx(), std::span<const float>(p)),
        history(ctx(), 2) {}

  void step(riner::ops::RinerStepOp& op, const riner::ops::StepParams& p,
            const riner::cl::Buffer<cl_uint>& words, riner::cl::Buffer<float>& grad) {
    op.step(p, words, {&invalid, &responses}, params, grad, history);
  }
};

// The device's gradient: grad plus the MLP's split-K slices added where they belong.
std::vector<double> full_gradient(const riner::ops::RinerStepOp& op,
                                  const riner::model::ParameterLayout& l,
                                  const std::vector<float>& grad) {
  std::vector<double> g(grad.begin(), grad.end());
  const std::vector<float> partials = op.mlp_partials().read();
  for (std::size_t s = 0; s < op.mlp_slices(); ++s) {
    for (std::size_t k = 0; k < l.mlp_params; ++k)
      g[l.mlp_offset + k] += partials[s * l.mlp_params + k];
  }
  return g;
}

std::vector<double> section(const std::vector<double>& v, std::size_t first, std::size_t last) {
  return {v.begin() + static_cast<long>(first), v.begin() + static_cast<long>(last)};
}

}  // namespace

TEST_SUITE("riner_step") {
  // Every plan's step against the twin on the scenarios with (or without) changing responses.
  void check_steps(bool changing_responses) {
    std::mt19937_64 rng(riner::test::seed() + 71);
    for (const Scenario& sc : scenarios()) {
      if (sc.changing_responses != changing_responses) continue;
      const riner::Geometry& g = sc.geometry;
      riner::RinerConfig c;
      c.encoding = {5, sc.features, g.is_3d() ? 10 : 14, 4, 48};  // 3D: hashed fine levels
      c.network = {sc.width, sc.hidden_layers};
      riner::TrainingConfig& t = c.training;
      t.sampler = sc.sampler;
      t.rays_per_step = sc.rays_per_step;
      t.views_per_step = 6;
      t.elements_per_step = 5;
      t.jitter = sc.jitter;
      const std::size_t per_view = g.n_u * (g.is_3d() ? g.n_v : 1);
      const std::size_t views = g.n_views();
      // Element 40 changes once, 45 twice, 50 dies half-way (its readings NaN from there on).
      std::vector<riner::model::ResponseChange> changes;
      if (sc.changing_responses) {
        changes = {
            {40, {views / 3}, false}, {45, {views / 4, views / 2}, false}, {50, {views / 2}, true}};
      }
      const riner::model::ResponseMap map(per_view, views, changes);
      const riner::model::ParameterLayout l =
          riner::model::make_layout(g.is_3d() ? 3 : 2, c.encoding, c.network, map.slots());
      const riner::model::RaySegments segments(g, 1.3 * g.voxel_mm, false);
      // Parameters away from the initial ones, so every layer matters.
      std::vector<float> params = riner::model::initial_parameters(l, riner::test::seed());
      std::uniform_real_distribution<float> grid(-0.2f, 0.2f), response(0.8f, 1.2f),
          logit(-1.0f, 2.0f), measured(0.0f, 2.0f);
      for (std::size_t i = 0; i < l.grid_params; ++i) params[i] = grid(rng);
      for (std::size_t slot = 0; slot < map.slots(); ++slot) {
        params[l.alpha_offset + slot] = response(rng);
        params[l.beta_offset + slot] = logit(rng);
      }
      std::vector<float> rho(views * per_view);
      for (float& v : rho) v = measured(rng);
      for (std::size_t e = 3; e < per_view; e += 17) {  // a few elements with unread readings
        for (std::size_t v = 0; v < views; ++v) rho[v * per_view + e] = NAN;
      }
      if (sc.changing_responses) {
        for (std::size_t v = views / 2; v < views; ++v) rho[v * per_view + 50] = NAN;
      }
      // Bounds (+inf: a beam the object stopped) at a floor some rays meet and some do not.
      const float starved_floor = 1.0f;
      for (std::size_t ray = 5; ray < rho.size(); ray += 7) {
        if (!std::isnan(rho[ray])) rho[ray] = INFINITY;
      }
      std::vector<std::uint32_t> invalid(map.slots(), 0);
      for (std::size_t ray = 0; ray < rho.size(); ++ray) {
        if (std::isnan(rho[ray])) ++invalid[map.slot(ray % per_view, ray / per_view)];
      }
      std::vector<float> level_weights(static_cast<std::size_t>(l.levels), 1.0f);
      if (sc.coarse_to_fine) level_weights.back() = 0.3f;

      DeviceInputs device(invalid, params, map);
      const std::vector<double> params_d(params.begin(), params.end());
      const riner::model::BatchSampler sampler(g, t);

      // The steps read every changing segment's slot (else the case would test nothing).
      std::vector<std::uint8_t> read(map.slots() - per_view, 0);
      using Shape = riner::ops::RinerStepOp::Shape;
      std::map<std::uint32_t, std::vector<double>> lanes_grad;  // by step
      std::map<std::uint32_t, std::vector<float>> lanes_sums;
      for (const char* kind : {"cpu", "cpu per-sample", "gpu"}) {
        riner::PlanConfig pc;
        pc.kind = kind[0] == 'c' ? "cpu" : "gpu";
        const riner::ExecutionPlan plan = riner::choose_execution_plan(ctx().info(), pc);
        riner::ops::RinerStepOp op(ctx(), l, plan, sampler.rays_per_step());
        const bool per_sample_cpu = std::string(kind) == "cpu per-sample";
        if (per_sample_cpu) op.use_shape(Shape::kPerSample);
        const std::string scenario = sc.name;
        const std::string kind_name = kind;
        for (std::uint32_t step : {3u, 11u}) {
          CAPTURE(scenario);
          CAPTURE(kind_name);
          CAPTURE(step);
          const riner::model::Batch batch = sampler.batch(step);
          riner::model::PackedBatch packed;
          riner::model::pack_batch(batch, segments, rho, per_view, level_weights, packed);
          const riner::cl::Buffer<cl_uint> words(ctx(), std::span<const cl_uint>(packed.words));
          riner::ops::StepParams p;
          riner::ops::set_batch_shape(packed, p);
          p.elements_per_view = static_cast<cl_uint>(per_view);
          p.seed = 12345;
          p.step = step;
          p.jitter = sc.jitter;
          p.hold_valid_beta = sc.hold_valid_beta;
          p.lambda = 0.05f;
          p.relative_beta_threshold = static_cast<float>(sc.relative_beta_threshold);
          p.data_weight = 0.7f;
          p.ring_lambda = static_cast<float>(sc.ring_lambda);
          p.starved_floor = starved_floor;
          p.block_first = batch.block_first;
          p.block_views = batch.block_views;
          p.block_elements = batch.block_elements;
          riner::cl::Buffer<float> grad(ctx(), std::vector<float>(l.total, 0.0f));
          device.step(op, p, words, grad);
          // The cpu plan's two shapes: the same ray sums and gradients to the bit.
          if (std::string(kind) == "cpu") {
            lanes_grad[step] = full_gradient(op, l, grad.read());
            lanes_sums[step] = op.ray_sums().read();
          }
          if (per_sample_cpu) {
            CHECK(op.ray_sums().read() == lanes_sums[step]);
            CHECK(full_gradient(op, l, grad.read()) == lanes_grad[step]);
          }

          riner::ref::StepInputs in;
          in.layout = &l;
          in.segments = &segments;
          in.measurement = &rho;
          in.starved_floor = starved_floor;
          in.elements_per_view = per_view;
          in.jitter = sc.jitter;
          in.seed = 12345;
          in.step = step;
          in.lambda = 0.05;
          in.ring_lambda = sc.ring_lambda;
          in.relative_beta_threshold = sc.relative_beta_threshold;
          in.data_weight = 0.7;
          in.level_weights = level_weights;
          in.hold_valid_beta = sc.hold_valid_beta;
          in.invalid_readings = &invalid;
          in.responses = sc.changing_responses ? &map : nullptr;
          const riner::ref::StepResult want = riner::ref::riner_step(in, batch, params_d);
          for (std::size_t slot = per_view; slot < map.slots(); ++slot)
            read[slot - per_view] |= want.grad[l.alpha_offset + slot] != 0.0;

          // float32 sums of ~100 samples against double: a few ulps of the sum.
          const std::size_t n = batch.rays.size();
          std::vector<float> sums = op.ray_sums().read();
          sums.resize(n);
          const auto sum_err = riner::test::compare(sums, want.sums);
          CHECK_MESSAGE(sum_err.rms_rel < riner::test::tolerance::kOnePass, sum_err.describe());
          std::vector<float> d_sums = op.ray_sum_gradients().read();
          d_sums.resize(n);
          const auto d_err = riner::test::compare(d_sums, want.d_sums);
          CHECK_MESSAGE(d_err.rms_rel < riner::test::tolerance::kOnePass, d_err.describe());
          const std::vector<float> losses = device.history.read();
          CHECK(losses[0] ==
                doctest::Approx(want.data_loss).epsilon(riner::test::tolerance::kOnePass));
          CHECK(losses[1] ==
                doctest::Approx(want.penalty).epsilon(riner::test::tolerance::kOnePass));
          // Gradients: sums over thousands of float32 products (the MLP's) and atomics in any
          // order (the gpu plan's grid) against double: 1e-4 of each section's norm.
          const std::vector<double> got = full_gradient(op, l, grad.read());
          const std::pair<const char*, std::pair<std::size_t, std::size_t>> sections[] = {
              {"grid", {0, l.grid_params}},
              {"mlp", {l.mlp_offset, l.mlp_offset + l.mlp_params}},
              {"alpha0", {l.alpha_offset, l.beta_offset}},
              {"beta0", {l.beta_offset, l.total}}};
          for (const auto& [name, range] : sections) {
            CAPTURE(name);
            const auto err = riner::test::compare(section(got, range.first, range.second),
                                                  section(want.grad, range.first, range.second));
            CHECK_MESSAGE(err.rms_rel < riner::test::tolerance::kChained, err.describe());
          }
        }
      }
      CHECK(std::count(read.begin(), read.end(), 1) == static_cast<long>(read.size()));
    }
  }

  TEST_CASE("each plan's step matches ref::riner_step on random parameters and batches") {
    check_steps(false);
  }

  // Also under oclgrind (test/CMakeLists.txt, oclgrind_response_slots).
  TEST_CASE("each plan's step matches ref::riner_step with responses changing part-way") {
    check_steps(true);
  }

  TEST_CASE("the cpu plan's step is bit-identical run to run") {
    const riner::Geometry g = riner::test::small_fan2d();
    riner::RinerConfig c;
    const riner::model::ParameterLayout l =
        riner::model::make_layout(2, {6, 2, 14, 4, 64}, {16, 1}, g.n_u);
    const riner::model::RaySegments segments(g, 1.5, false);
    std::vector<float> params = riner::model::initial_parameters(l, 3);
    std::mt19937_64 rng(riner::test::seed() + 5);
    std::uniform_real_distribution<float> u(-0.2f, 0.2f);
    for (std::size_t i = 0; i < l.grid_params; ++i) params[i] = u(rng);
    std::vector<float> rho(g.n_views() * g.n_u, 0.5f);
    std::vector<std::uint32_t> invalid(g.n_u, 0);
    DeviceInputs device(invalid, params, riner::model::ResponseMap(g.n_u));
    c.training.rays_per_step = 200;
    const riner::model::BatchSampler sampler(g, c.training);
    riner::PlanConfig pc;
    pc.kind = "cpu";
    riner::ops::RinerStepOp op(ctx(), l, riner::choose_execution_plan(ctx().info(), pc), 200);
    riner::model::PackedBatch packed;
    riner::model::pack_batch(sampler.batch(1), segments, rho, g.n_u, std::vector<float>(6, 1.0f),
                             packed);
    const riner::cl::Buffer<cl_uint> words(ctx(), std::span<const cl_uint>(packed.words));
    riner::ops::StepParams p;
    riner::ops::set_batch_shape(packed, p);
    p.elements_per_view = static_cast<cl_uint>(g.n_u);
    p.lambda = 0.01f;
    std::vector<double> first;
    for (int run = 0; run < 2; ++run) {
      riner::cl::Buffer<float> grad(ctx(), std::vector<float>(l.total, 0.0f));
      device.step(op, p, words, grad);
      const std::vector<double> g_run = full_gradient(op, l, grad.read());
      if (run == 0)
        first = g_run;
      else
        CHECK(g_run == first);
    }
  }
}
