// The OpenCL training against the reference engine, and tiny end-to-end reconstructions.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "model/broad_even_hold.hpp"
#include "model/ray_segments.hpp"
#include "riner/destripe.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/metrics.hpp"
#include "riner/reconstructor.hpp"
#include "support/fixture.hpp"
#include "support/geometries.hpp"
#include "support/partial_scan.hpp"
#include "support/tiny_problem.hpp"
#include "support/tolerances.hpp"
#include "training/trainer.hpp"

namespace {

// One configuration built on the OpenCL device and on the reference engine.
struct BothEngines {
  riner::Reconstructor device;
  riner::Reconstructor reference;
};

BothEngines both_engines(const riner::Scan& scan, riner::RinerConfig c) {
  riner::Reconstructor device(scan, c, riner::test::device());
  c.engine = riner::Engine::kReference;
  return {std::move(device), riner::Reconstructor(scan, c)};
}

}  // namespace

TEST_SUITE("riner_training") {
  TEST_CASE("the first 20 steps' losses agree between OpenCL and the reference to 1e-3") {
    const riner::test::TinyProblem t = riner::test::tiny_problem(2);
    for (riner::Sampler sampler : {riner::Sampler::kUniform, riner::Sampler::kMixed}) {
      riner::RinerConfig c = riner::test::tiny_config();
      c.training.sampler = sampler;
      c.training.elements_per_step = 6;
      c.training.views_per_step = 5;
      c.training.jitter = true;
      c.training.ring_lambda = sampler == riner::Sampler::kMixed ? 5.0 : 0.0;
      c.training.level_warmup_steps = 5;
      auto [device, reference] = both_engines(t.scan, c);
      device.step(20);
      reference.step(20);
      const auto a = device.history();
      const auto b = reference.history();
      REQUIRE(a.size() == 20);
      REQUIRE(b.size() == 20);
      for (int i = 0; i < 20; ++i) {
        CAPTURE(i);
        CHECK(a[i].data_loss ==
              doctest::Approx(b[i].data_loss).epsilon(riner::test::tolerance::kTraining));
        CHECK(a[i].penalty ==
              doctest::Approx(b[i].penalty).epsilon(riner::test::tolerance::kTraining));
      }
      const riner::Array ia = device.image();
      const riner::Array ib = reference.image();
      double diff = 0.0, norm = 0.0;
      for (std::size_t i = 0; i < ia.size(); ++i) {
        diff += (ia.data[i] - ib.data[i]) * (ia.data[i] - ib.data[i]);
        norm += static_cast<double>(ib.data[i]) * ib.data[i];
      }
      CHECK(std::sqrt(diff / norm) < riner::test::tolerance::kTraining);
    }
  }

  TEST_CASE("the beta warm-up holds every element without invalid readings, on both engines") {
    // One dead element (+inf readings but one 0, as the paper's dead elements read: an element
    // reading nothing at all starts switched off): its beta learns from step 0; every other
    // stays put.
    riner::test::TinyProblem t = riner::test::tiny_problem(5);
    for (std::size_t e = 0; e < t.alpha.size(); ++e) {
      if (t.alpha.data[e] == 0.0f) t.scan.measurement.data[e] = 0.0f;  // view 0
    }
    riner::RinerConfig c = riner::test::tiny_config();
    c.training.beta_warmup_steps = 1000;
    auto [device, reference] = both_engines(t.scan, c);
    const riner::Array before = device.trained_beta();
    device.step(40);
    reference.step(40);
    const riner::Array a = device.trained_beta();
    const riner::Array b = reference.trained_beta();
    int dead = 0;
    for (std::size_t e = 0; e < a.size(); ++e) {
      CAPTURE(e);
      CHECK(a.data[e] == doctest::Approx(b.data[e]).epsilon(riner::test::tolerance::kTraining));
      if (t.alpha.data[e] != 0.0f) {
        CHECK(a.data[e] == before.data[e]);
        CHECK(b.data[e] == before.data[e]);
      } else {
        ++dead;
        CHECK(a.data[e] < before.data[e] - 0.01f);
      }
    }
    CHECK(dead == 1);
  }

  TEST_CASE("alpha's broad even hold: both engines agree; only alpha's narrow part learns") {
    // 40 steps inside a warm-up holding alpha's part even about the axis and broader than
    // 3 pixels: alpha moves (the rings' narrow offsets), its broad even part hardly. Over a
    // full turn: a 180-degree scan holds all of alpha.
    const riner::test::TinyProblem t = riner::test::tiny_problem(2, 1, 2.0 * M_PI);
    riner::RinerConfig c = riner::test::tiny_config();
    c.rings.air_reference = c.rings.gradient_reference = c.rings.response_reference =
        c.rings.mirror_reference = false;
    c.training.alpha_warmup_steps = 1000;
    c.training.alpha_warmup_broad_px = 3.0;
    auto [device, reference] = both_engines(t.scan, c);
    device.step(40);
    reference.step(40);
    const riner::Array a = device.trained_alpha();
    const riner::Array b = reference.trained_alpha();
    const riner::model::BroadEvenHold hold(t.scan.geometry, 3.0,
                                           std::vector<float>(a.size(), 1.0f));
    std::vector<double> log_alpha(a.size());
    double moved = 0.0;
    for (std::size_t e = 0; e < a.size(); ++e) {
      CAPTURE(e);
      CHECK(a.data[e] == doctest::Approx(b.data[e]).epsilon(riner::test::tolerance::kTraining));
      log_alpha[e] = std::log(a.data[e]);
      moved += log_alpha[e] * log_alpha[e];
    }
    const std::vector<double> broad = hold.broad_even(log_alpha);
    double broad_squares = 0.0;
    for (double v : broad) broad_squares += v * v;
    MESSAGE("alpha's change rms ", std::sqrt(moved / a.size()), ", its broad even part ",
            std::sqrt(broad_squares / a.size()));
    CHECK(std::sqrt(moved / a.size()) > 1e-3);
    CHECK(broad_squares < 0.01 * moved);
  }

  TEST_CASE("tail averaging: alpha is the mean of the snapshots' alphas; training unchanged") {
    // 60 steps, a tail of 30: snapshots after steps 39, 49 and 59 (0-based). The run without
    // averaging gives the snapshots; the run with it must give their mean, on both engines.
    const riner::test::TinyProblem t = riner::test::tiny_problem(5);
    for (riner::Engine engine : {riner::Engine::kOpenCL, riner::Engine::kReference}) {
      CAPTURE(riner::engine_name(engine));
      riner::RinerConfig c = riner::test::tiny_config();
      c.engine = engine;
      c.training.steps = 60;
      c.rings.air_reference = c.rings.gradient_reference = c.rings.response_reference =
          c.rings.mirror_reference = false;
      c.training.tail_average_steps = 0;
      riner::Reconstructor last(t.scan, c, riner::test::device());
      c.training.tail_average_steps = 30;
      riner::Reconstructor averaged(t.scan, c, riner::test::device());
      std::vector<double> mean(t.scan.geometry.n_u, 0.0);
      for (int s = 0; s < 60; ++s) {
        last.step(1);
        if (s == 39 || s == 49 || s == 59) {
          const riner::Array a = last.alpha();
          for (std::size_t e = 0; e < mean.size(); ++e) mean[e] += a.data[e] / 3.0;
        }
      }
      averaged.step(60);
      CHECK(averaged.stats().tail_average_snapshots == 3);
      CHECK(last.stats().tail_average_snapshots == 0);
      const auto h_last = last.history();
      const auto h_averaged = averaged.history();
      REQUIRE(h_last.size() == h_averaged.size());
      for (std::size_t i = 0; i < h_last.size(); ++i) {
        CHECK(h_averaged[i].data_loss == h_last[i].data_loss);
      }
      const riner::Array a = averaged.alpha();
      const riner::Array final_alpha = last.alpha();
      double moved = 0.0;
      for (std::size_t e = 0; e < mean.size(); ++e) {
        CAPTURE(e);
        CHECK(a.data[e] == doctest::Approx(mean[e]).epsilon(1e-6));
        moved = std::max(moved, std::fabs(final_alpha.data[e] - mean[e]));
      }
      CHECK(moved > 1e-4);  // the mean differs from the last step's alpha
      // Past the planned steps the result follows training again: the last step's alpha.
      last.step(1);
      averaged.step(1);
      CHECK(averaged.stats().tail_average_snapshots == 0);
      const riner::Array a_after = averaged.alpha();
      const riner::Array last_after = last.alpha();
      for (std::size_t e = 0; e < mean.size(); ++e) CHECK(a_after.data[e] == last_after.data[e]);
    }
  }

  TEST_CASE("a tiny ring scan: the loss falls, the image beats FBP, the dead element is found") {
    // 48 x 48 Shepp-Logan, 90 views over 180 degrees, one dead element (seed 5 puts it where
    // its rays cross the object). Measured: loss / 110, 21.1 dB against FBP's 16.2, beta 0.20.
    const riner::test::TinyProblem t = riner::test::tiny_problem(5);
    riner::RinerConfig c = riner::test::tiny_config();
    c.training.steps = 1500;
    riner::Reconstructor r(t.scan, c, riner::test::device());
    r.run();
    const auto history = r.history();
    double early = 0.0, late = 0.0;
    for (int i = 0; i < 50; ++i) {
      early += history[static_cast<std::size_t>(i)].data_loss;
      late += history[history.size() - 1 - static_cast<std::size_t>(i)].data_loss;
    }
    CHECK(late < early / 10.0);
    const riner::Array mask = riner::circle_mask(t.truth.shape, 0.9);
    riner::FbpOptions fbp_options;
    fbp_options.device = riner::test::device();
    const riner::ImageMetrics fbp =
        riner::compare_images(riner::fbp(t.scan, fbp_options), t.truth, &mask);
    const riner::ImageMetrics m = riner::compare_images(r.image(), t.truth, &mask);
    MESSAGE("tiny parallel scan: Riner " << m.psnr << " dB, FBP " << fbp.psnr
                                         << " dB inside the circle");
    CHECK(m.psnr > fbp.psnr + 3.0);
    const riner::Array beta = r.beta();
    int dead = 0;
    for (std::size_t e = 0; e < beta.size(); ++e) {
      if (t.alpha.data[e] != 0.0f) continue;
      ++dead;
      CHECK(beta.data[e] < 0.5f);
    }
    CHECK(dead == 1);
  }

  TEST_CASE("repeated runs with the same seed are bit-identical (partitioned gradients)") {
    const riner::test::TinyProblem t = riner::test::tiny_problem(5);
    riner::RinerConfig c = riner::test::tiny_config();
    c.training.steps = 30;
    riner::Reconstructor a(t.scan, c, riner::test::device());
    riner::Reconstructor b(t.scan, c, riner::test::device());
    a.run();
    b.run();
    CHECK(a.image().data == b.image().data);
    CHECK(a.alpha().data == b.alpha().data);
  }

  TEST_CASE("stop_on_plateau ends training in the last learning-rate phase, not before") {
    const riner::test::TinyProblem t = riner::test::tiny_problem(5);
    riner::RinerConfig c = riner::test::tiny_config();
    c.training.steps = 400;
    c.training.lr_decay_steps = 100;  // the last phase starts at 300
    c.training.stop_on_plateau = true;
    c.training.plateau_window = 20;
    c.training.plateau_tolerance = 0.9;  // any window short of a 90% drop is a plateau
    riner::Reconstructor r(t.scan, c, riner::test::device());
    r.run();
    const riner::TrainingStats s = r.stats();
    CHECK(s.stopped_on_plateau);
    CHECK(s.steps_planned == 400);
    CHECK(s.steps >= 300 + 2 * 20);
    CHECK(s.steps < 400);
    CHECK(r.history().size() == static_cast<std::size_t>(s.steps));
    c.training.stop_on_plateau = false;
    riner::Reconstructor full(t.scan, c, riner::test::device());
    full.run();
    CHECK_FALSE(full.stats().stopped_on_plateau);
    CHECK(full.stats().steps == 400);
  }

  TEST_CASE("partial rings: a response per segment of views, near the truth, a better image") {
    // 5 elements change and 2 die part-way (test_response_changes: all 7 are found on seed 6).
    const riner::test::PartialScan s = riner::test::partial_scan(5, 2, 6);
    riner::RinerConfig c;
    c.training.steps = 4000;
    riner::Reconstructor on(s.scan, c, riner::test::device());
    on.run();
    c.training.partial_responses = false;
    riner::Reconstructor off(s.scan, c, riner::test::device());
    off.run();
    const double psnr_on = riner::psnr(on.image(), s.ground_truth);
    const double psnr_off = riner::psnr(off.image(), s.ground_truth);
    MESSAGE("PSNR with partial responses " << psnr_on << " dB, without " << psnr_off);
    CHECK(psnr_on > psnr_off + 0.8);  // 28.75 against 27.51 (2026-11-27, smooth rate decay)

    const std::vector<riner::ChangingElement> changing = on.changing_elements();
    CHECK(changing.size() == 7);
    CHECK(off.changing_elements().empty());
    const std::size_t elements = s.scan.geometry.n_u;
    const std::vector<std::size_t> dead = on.dead_elements();
    for (const riner::ChangingElement& e : changing) {
      CAPTURE(e.element);
      REQUIRE(e.segments.size() == 2);
      for (const riner::ResponseSegment& segment : e.segments) {
        CAPTURE(segment.first_view);
        const float truth = s.alpha.data[segment.first_view * elements + e.element];
        if (truth == 0.0f) {
          // A dead segment is switched off where its rays cross the object (where they miss it,
          // the dead readings, counted as 0, agree with air and beta rises to ~1: 0.986 for
          // element 112 under the smooth rate decay, 0.99+ in steps); the element is not dead.
          if (segment.beta < 0.95) CHECK(segment.beta < riner::Reconstructor::kDeadBelowBeta);
          CHECK(std::find(dead.begin(), dead.end(), e.element) == dead.end());
        } else {
          CHECK(std::fabs(std::log(segment.alpha / truth)) < 0.12);
          CHECK(segment.beta > riner::Reconstructor::kDeadBelowBeta);
        }
      }
    }
    const riner::Array by_view = on.alpha_by_view();
    REQUIRE(by_view.shape == std::vector<std::size_t>{240, elements});
    // An element whose response holds over the scan reads, in every view, the response the
    // corrections left it (alpha_by_view is formed after the last of them).
    const riner::Array alpha = on.result().alpha;
    std::vector<bool> changes(elements, false);
    for (const riner::ChangingElement& e : changing) changes[e.element] = true;
    for (std::size_t e = 0; e < elements; ++e) {
      if (changes[e]) continue;
      for (std::size_t v = 0; v < 240; v += 17) {
        CHECK(by_view.data[v * elements + e] == doctest::Approx(alpha.data[e]).epsilon(1e-6));
      }
    }
  }

  TEST_CASE("bad inputs are InputErrors") {
    const riner::test::TinyProblem t = riner::test::tiny_problem(6);
    riner::RinerConfig c = riner::test::tiny_config();
    riner::Scan wrong = t.scan;
    wrong.measurement = riner::Array({10, 50}, 1.0f);
    CHECK_THROWS_WITH_AS(riner::Reconstructor(wrong, c, riner::test::device()),
                         doctest::Contains("but the geometry lists 90 angles"), riner::InputError);
    riner::Scan all_nan = t.scan;
    for (float& v : all_nan.measurement.data) v = NAN;
    all_nan.non_finite = all_nan.measurement.size();
    CHECK_THROWS_WITH_AS(riner::Reconstructor(all_nan, c, riner::test::device()),
                         doctest::Contains("all 4500 values are NaN or infinite"),
                         riner::InputError);
    riner::RinerConfig bad = c;
    bad.network.width = 20;
    CHECK_THROWS_AS(riner::Reconstructor(t.scan, bad, riner::test::device()), riner::InputError);
    riner::Scan offside = t.scan;
    offside.geometry.offset_u = 500.0;  // every ray misses the grid
    CHECK_THROWS_WITH_AS(riner::Reconstructor(offside, c, riner::test::device()),
                         doctest::Contains("no detector ray crosses the reconstruction grid"),
                         riner::InputError);
  }

  TEST_CASE("training.steps -1 is the scan's: 24000 for a slice, 12000 for a volume") {
    riner::RinerConfig c = riner::test::tiny_config();
    c.training.steps = riner::TrainingConfig::kScanSteps;
    c.training.lr_decay_steps = 0;
    const riner::TrainingConfig& slice =
        riner::Reconstructor(riner::test::tiny_problem(3).scan, c, riner::test::device())
            .config()
            .training;
    CHECK(slice.steps == 24000);
    CHECK(slice.decay_interval() == 6000);  // a quarter of the resolved steps
    const riner::Geometry g = riner::test::small_cone3d();
    riner::Array sino(g.measurement_shape());
    for (std::size_t i = 0; i < sino.size(); ++i) sino.data[i] = 0.1f + 0.01f * (i % 7);
    const riner::Scan volume{sino, g, 0};
    CHECK(riner::Reconstructor(volume, c, riner::test::device()).config().training.steps == 12000);
    c.training.steps = 77;  // an explicit count stays
    CHECK(riner::Reconstructor(volume, c, riner::test::device()).config().training.steps == 77);
  }

  TEST_CASE("a slice's steps left to the scan grow until each ray is drawn min_draws_per_ray times") {
    // 50 x 90 = 4500 rays, one ray per step: 10 draws need 45 000 steps, more than 24 000.
    const riner::Scan scan = riner::test::tiny_problem(3).scan;
    riner::RinerConfig c = riner::test::tiny_config();
    c.training.steps = riner::TrainingConfig::kScanSteps;
    c.training.rays_per_step = 1;
    const riner::Reconstructor raised(scan, c, riner::test::device());
    CHECK(raised.config().training.steps == 45000);
    CHECK(raised.stats().steps_planned == 45000);
    CHECK(raised.stats().rays_per_step == 1);
    CHECK(raised.stats().draws_per_ray_planned == doctest::Approx(10.0));
    // A batch over the CPU plan's 160 rays (a GPU's 640) keeps the steps of 160: 1000 draws
    // of 4500 rays in batches of 160 are 28 125 steps, and each ray is drawn 4000 times.
    c.training.rays_per_step = 640;
    c.training.min_draws_per_ray = 1000.0;
    const riner::Reconstructor wide(scan, c, riner::test::device());
    CHECK(wide.config().training.steps == 28125);
    CHECK(wide.stats().draws_per_ray_planned == doctest::Approx(4000.0));
    c.training.rays_per_step = 1;
    c.training.min_draws_per_ray = 2.5;  // fewer than the default's draws: the default stays
    CHECK(riner::Reconstructor(scan, c, riner::test::device()).config().training.steps == 24000);
    c.training.min_draws_per_ray = 0.0;  // off
    CHECK(riner::Reconstructor(scan, c, riner::test::device()).config().training.steps == 24000);
    c.training.min_draws_per_ray = 10.0;
    c.training.steps = 500;  // an explicit count stays
    CHECK(riner::Reconstructor(scan, c, riner::test::device()).config().training.steps == 500);
    c.training.steps = riner::TrainingConfig::kScanSteps;
    c.training.sampler = riner::Sampler::kViewsTimesElements;  // its batch is views x elements
    CHECK(riner::Reconstructor(scan, c, riner::test::device()).config().training.steps == 24000);
  }

  TEST_CASE("a volume short of samples: steps until each voxel is sampled "
            "min_samples_per_voxel times, the volume's table; else the slice's") {
    const riner::Geometry g = riner::test::small_cone3d();
    riner::Array sino(g.measurement_shape());
    for (std::size_t i = 0; i < sino.size(); ++i) sino.data[i] = 0.1f + 0.01f * (i % 7);
    const riner::Scan volume{sino, g, 0};
    riner::RinerConfig c = riner::test::tiny_config();
    c.training.steps = riner::TrainingConfig::kScanSteps;
    c.encoding.log2_table_size = riner::EncodingConfig::kScanTable;
    c.training.rays_per_step = 64;
    c.training.min_samples_per_voxel = 2000.0;
    // The rays' mean samples inside the grid, as the trainer steps along them.
    const std::vector<riner::model::RaySegment> segments =
        riner::model::ray_segments(g, c.training.sample_spacing * g.voxel_mm,
                                   c.training.circle_region);
    double samples = 0.0;
    for (const riner::model::RaySegment& s : segments) samples += s.count;
    const double per_step = 64.0 * samples / static_cast<double>(segments.size()) /
                            static_cast<double>(riner::shape_size(g.volume_shape));
    const int expected = static_cast<int>(std::ceil(2000.0 / per_step));
    REQUIRE(expected > riner::TrainingConfig::kSteps3d);
    const riner::Reconstructor raised(volume, c, riner::test::device());
    CHECK(raised.config().training.steps == expected);
    CHECK(raised.stats().samples_per_voxel_planned == doctest::Approx(2000.0).epsilon(1e-3));
    CHECK(raised.config().encoding.log2_table_size == riner::EncodingConfig::kLog2TableVolume);
    // An explicit count keeps the volume's table: it follows the scan.
    c.training.steps = 300;
    const riner::Reconstructor counted(volume, c, riner::test::device());
    CHECK(counted.config().training.steps == 300);
    CHECK(counted.config().encoding.log2_table_size == riner::EncodingConfig::kLog2TableVolume);
    // Sampled enough at the floor (a thin slab): the floor, the slice's table.
    c.training.steps = riner::TrainingConfig::kScanSteps;
    c.training.min_samples_per_voxel = 0.5 * riner::TrainingConfig::kSteps3d * per_step;
    const riner::Reconstructor enough(volume, c, riner::test::device());
    CHECK(enough.config().training.steps == riner::TrainingConfig::kSteps3d);
    CHECK(enough.config().encoding.log2_table_size == riner::EncodingConfig::kLog2TableSlice);
    c.training.min_samples_per_voxel = 0.0;  // off
    CHECK(riner::Reconstructor(volume, c, riner::test::device()).config().training.steps ==
          riner::TrainingConfig::kSteps3d);
    // An explicit table stays.
    c.training.min_samples_per_voxel = 2000.0;
    c.encoding.log2_table_size = 12;
    CHECK(riner::Reconstructor(volume, c, riner::test::device()).config().encoding.log2_table_size ==
          12);
    // A slice's are the slice's.
    c = riner::test::tiny_config();
    c.encoding.log2_table_size = riner::EncodingConfig::kScanTable;
    const riner::Reconstructor slice(riner::test::tiny_problem(3).scan, c, riner::test::device());
    CHECK(slice.config().encoding.log2_table_size == riner::EncodingConfig::kLog2TableSlice);
  }

  TEST_CASE("zero steps leave the initial field; alpha and beta start at 1 and sigmoid(1)") {
    // But the dead element, which reads nothing: its beta starts near 0.
    const riner::test::TinyProblem t = riner::test::tiny_problem(7);
    riner::RinerConfig c = riner::test::tiny_config();
    c.training.steps = 0;
    riner::Reconstructor r(t.scan, c, riner::test::device());
    r.run();
    CHECK(r.steps_done() == 0);
    // trained_alpha(): alpha() also carries the ring corrections of the initial field's noise.
    for (float a : r.trained_alpha().data) CHECK(a == 1.0f);
    const riner::Array beta = r.trained_beta();
    for (std::size_t e = 0; e < beta.size(); ++e) {
      const double beta0 = t.alpha.data[e] == 0.0f ? riner::TrainingConfig{}.unread_beta0 : 1.0;
      CHECK(beta.data[e] == doctest::Approx(1.0 / (1.0 + std::exp(-beta0))));
    }
    CHECK(r.history().empty());
  }

  TEST_CASE("warm start: alpha0 is the filter's response, the field fits the destriped FBP") {
    const riner::test::TinyProblem t = riner::test::tiny_problem(5);
    riner::RinerConfig c = riner::test::tiny_config();
    c.training.steps = 0;
    c.training.warm_start = "normalise";
    c.training.warm_start_steps = 400;
    auto [device, reference] = both_engines(t.scan, c);
    REQUIRE(device.stats().warm_start.has_value());
    REQUIRE(reference.stats().warm_start.has_value());
    CHECK(device.stats().warm_start->method == "normalise");
    CHECK(device.stats().warm_start->fit_pixels > 0);

    // alpha0: exp(-what the filter removed), clamped to [0.05, 20] (the dead element's).
    riner::DestripeOptions filter;
    filter.method = riner::DestripeMethod::kNormalise;
    filter.engine = riner::Engine::kReference;
    riner::DestripeReport report;
    const riner::Array destriped = riner::destripe(t.scan.measurement, t.scan.geometry, filter,
                                                   &report);
    const riner::Array alpha = device.trained_alpha();
    REQUIRE(alpha.size() == report.removed.size());
    for (std::size_t e = 0; e < alpha.size(); ++e) {
      CAPTURE(e);
      const double expected = std::clamp(std::exp(-report.removed.data[e]), 0.05f, 20.0f);
      CHECK(alpha.data[e] == doctest::Approx(expected).epsilon(1e-5));
      // The filter runs on each engine's own path (float on the device, double on the CPU).
      CHECK(reference.trained_alpha().data[e] == doctest::Approx(alpha.data[e]).epsilon(1e-5));
    }

    // The field: the destriped scan's FBP after the fit, far from the random start, on both
    // engines. Measured: relative error 0.19 on both, against 1.0 for the random start.
    riner::FbpOptions fbp_options;
    fbp_options.device = riner::test::device();
    const riner::Array fbp = riner::fbp({destriped, t.scan.geometry, 0}, fbp_options);
    const auto relative_error = [&](const riner::Array& image) {
      double diff = 0.0, norm = 0.0;
      for (std::size_t i = 0; i < fbp.size(); ++i) {
        diff += (image.data[i] - fbp.data[i]) * (image.data[i] - fbp.data[i]);
        norm += static_cast<double>(fbp.data[i]) * fbp.data[i];
      }
      return std::sqrt(diff / norm);
    };
    const double on_device = relative_error(device.field_image());
    const double on_reference = relative_error(reference.field_image());
    MESSAGE("warm start fit: relative error to the destriped FBP " << on_device << " (OpenCL), "
                                                                   << on_reference
                                                                   << " (reference)");
    CHECK(on_device < 0.25);
    CHECK(on_reference < 0.25);
    CHECK(device.stats().warm_start->fit_residual ==
          doctest::Approx(reference.stats().warm_start->fit_residual).epsilon(0.05));
  }

  TEST_CASE("warm start: a short training from it beats the same from a cold start") {
    // 48 x 48 Shepp-Logan with rings, 100 steps. Measured: warm 20.2 dB, cold 17.1 (at 50
    // steps 20.2 and 14.3; by 300 the cold start has caught up on this tiny scan: 20.3).
    const riner::test::TinyProblem t = riner::test::tiny_problem(5);
    const riner::Array mask = riner::circle_mask(t.truth.shape, 0.9);
    riner::RinerConfig c = riner::test::tiny_config();
    c.training.steps = 100;
    // The trainings compared: the readings' detail given back afterwards (detail.residual) lifts
    // the cold start's 100 steps to 25 dB on its own.
    c.residual_detail.enabled = false;
    riner::Reconstructor cold(t.scan, c, riner::test::device());
    cold.run();
    c.training.warm_start = "normalise";
    riner::Reconstructor warm(t.scan, c, riner::test::device());
    warm.run();
    const double cold_psnr = riner::compare_images(cold.image(), t.truth, &mask).psnr;
    const double warm_psnr = riner::compare_images(warm.image(), t.truth, &mask).psnr;
    MESSAGE("100 steps: warm " << warm_psnr << " dB, cold " << cold_psnr << " dB");
    CHECK(warm_psnr > cold_psnr + 2.0);
    // The warm schedule: steps as given (only -1 is cut to a third), the rate scaled.
    CHECK(warm.config().training.steps == 100);
    CHECK(warm.config().training.learning_rate ==
          doctest::Approx(c.training.learning_rate * c.training.warm_start_lr_scale));
  }

  TEST_CASE("warm start: an unknown filter is an InputError") {
    riner::RinerConfig c;
    CHECK_THROWS_AS(c.update_from_json(R"({"training": {"warm_start": "wavelets"}})", "c.json"),
                    riner::InputError);
  }
}
