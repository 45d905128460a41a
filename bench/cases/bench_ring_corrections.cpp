// Compares the ring corrections on the same trained fields: each DeepLesion slice (paper
// protocol) is trained once at the current settings, then the field goes through the air
// reference alone, the air reference plus the radial-gradient correction, and those plus the
// detector-response correction at several scales (and the gradient correction once more after
// it, as reconstructions run it), so the differences are the corrections' only.
//
//   riner_bench --case=ring_corrections [--first=0] [--last=9] [--seed-offset=0] [--config=JSON]
//               [--json=FILE] [--images=DIR]
//   --images: per slice, DIR/SLICE_{result,field,truth}.npy and SLICE_{alpha,true_alpha}.npy
//   (what `riner reconstruct` writes, the trained field and the responses), for analysis.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "harness.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/reconstructor.hpp"
#include "riner/ring_correction.hpp"
#include "scenes.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

struct Variant {
  std::string name;
  bool air = true;
  double gradient_scale_px = 0.0;  // 0: no gradient correction
  double response_scale_px = 0.0;  // 0: no detector-response correction
  double min_even_to_odd = riner::ResponseRingSettings{}.min_even_to_odd;
  bool gradient_after_response = false;
};

constexpr const char* kReconstruct = "reconstruct";

struct Totals {
  double psnr = 0.0, ssim = 0.0, alpha_error = 0.0;
};

std::vector<Result> ring_corrections(const Options& o) {
  const int first = o.get_int("first", 0);
  const int last = o.get_int("last", o.size == "tiny" ? first : 9);
  riner::RinerConfig config = riner::bench::config_from(o);
  if (o.size == "tiny") config.training.steps = std::min(config.training.steps_for(false), 200);
  riner::Device device = riner::Device::open(o.device);
  const riner::Projector projector(riner::preset_geometry("fan2d-paper"), riner::Engine::kOpenCL,
                                   device);
  const std::vector<Variant> variants = {
      {"field", false, 0.0, 0.0},
      {"air", true, 0.0, 0.0},
      {"air + gradient", true, 12.0, 0.0},
      {"air + gradient + response 24 px", true, 12.0, 24.0},
      {"air + gradient + response 24 px, ungated", true, 12.0, 24.0, 0.0},
      {"air + gradient + response 24 px + gradient", true, 12.0, 24.0,
       riner::ResponseRingSettings{}.min_even_to_odd, true},
      {"air + gradient + response 16 px", true, 12.0, 16.0},
      {"air + gradient + response 32 px", true, 12.0, 32.0}};
  std::vector<Totals> totals(variants.size() + 1);  // the last: kReconstruct
  std::vector<Result> results;
  const std::filesystem::path images_dir = o.get("images", "");
  if (!images_dir.empty()) std::filesystem::create_directories(images_dir);
  int scenes = 0;
  for (int index = first; index <= last; ++index, ++scenes) {
    const riner::bench::RingScene scene = riner::bench::paper_scene(o, index, projector);
    const riner::Geometry& g = scene.sim.scan.geometry;
    const auto constructed = std::chrono::steady_clock::now();
    riner::Reconstructor r(scene.sim.scan, config, device);
    // Before training: the air carving, the evidence, a warm start's filter and fit.
    const double setup_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - constructed).count();
    r.run();
    const riner::Array field = r.field_image();
    const riner::Array alpha = r.trained_alpha();
    const riner::Array beta = r.trained_beta();
    const std::vector<std::size_t> dead = r.dead_elements();
    const riner::RingCorrection air =
        riner::correct_rings_from_air(field, alpha, g, config.rings.air);
    nlohmann::json row{{"scene", scene.name},
                       {"seconds", r.stats().seconds},
                       {"setup_seconds", setup_seconds},
                       {"warm_start_seconds",
                        r.stats().warm_start ? r.stats().warm_start->seconds : 0.0},
                       {"samples_per_second", r.stats().samples / r.stats().seconds},
                       {"steps", r.stats().steps},
                       {"stopped_on_plateau", r.stats().stopped_on_plateau},
                       {"samples_kept_fraction", r.stats().samples_kept_fraction},
                       {"detector", riner::bench::detector_accuracy(alpha, beta, scene.sim)}};
    std::string line =
        riner::bench::format("%-20s %6.1f s (+%.1f s setup) %5d steps", scene.name.c_str(),
                             r.stats().seconds, setup_seconds, r.stats().steps);
    for (std::size_t v = 0; v < variants.size(); ++v) {
      riner::Array image = variants[v].air ? air.image : field;
      riner::Array response = variants[v].air ? air.alpha : alpha;
      double change = 0.0;
      double response_change = 0.0;
      double even_to_odd = 0.0;
      // The radial-gradient step on the current image and alpha; its response change.
      const auto gradient_step = [&] {
        riner::GradientRingSettings settings = config.rings.gradient;
        settings.scale_px = variants[v].gradient_scale_px;
        const riner::RingCorrection c =
            riner::correct_rings_from_gradient(image, response, g, settings);
        image = c.image;
        response = c.alpha;
        return c.applied ? c.mean_response_change : -1.0;
      };
      if (variants[v].gradient_scale_px > 0.0) change = gradient_step();
      if (variants[v].response_scale_px > 0.0) {
        riner::ResponseRingSettings settings = config.rings.response;
        settings.scale_px = variants[v].response_scale_px;
        settings.min_even_to_odd = variants[v].min_even_to_odd;
        const riner::RingCorrection c =
            riner::correct_rings_from_response(image, response, g, dead, settings);
        image = c.image;
        response = c.alpha;
        response_change = c.applied ? c.mean_response_change : -1.0;
        even_to_odd = std::isfinite(c.even_to_odd) ? c.even_to_odd : 1e9;
      }
      if (variants[v].gradient_after_response) gradient_step();
      const riner::ImageMetrics m = riner::compare_images(image, scene.sim.ground_truth);
      const double alpha_error =
          riner::bench::detector_accuracy(response, beta, scene.sim)["alpha_mae_live"]
              .get<double>();
      totals[v].psnr += m.psnr;
      totals[v].ssim += m.ssim;
      totals[v].alpha_error += alpha_error;
      row[variants[v].name] = {{"psnr", m.psnr},
                               {"ssim", m.ssim},
                               {"alpha_mae_live", alpha_error},
                               {"gradient_response_change", change},
                               {"response_response_change", response_change},
                               {"even_to_odd", even_to_odd}};
      line += riner::bench::format(" | %s %.2f/%.3f", variants[v].name.c_str(), m.psnr, m.ssim);
    }
    // What `riner reconstruct` writes: the corrections as the reconstructor chains them, and
    // the air training skipped left at 0.
    {
      const riner::ReconstructionResult result = r.result();
      const riner::ImageMetrics m = riner::compare_images(result.image, scene.sim.ground_truth);
      const double alpha_error =
          riner::bench::detector_accuracy(result.alpha, beta, scene.sim)["alpha_mae_live"]
              .get<double>();
      totals.back().psnr += m.psnr;
      totals.back().ssim += m.ssim;
      totals.back().alpha_error += alpha_error;
      row[kReconstruct] = {{"psnr", m.psnr}, {"ssim", m.ssim}, {"alpha_mae_live", alpha_error}};
      line += riner::bench::format(" | %s %.2f/%.3f", kReconstruct, m.psnr, m.ssim);
      if (!images_dir.empty()) {
        const std::string name = "slice_" + std::to_string(index);
        const auto save = [&](const char* what, const riner::Array& a) {
          riner::write_array(images_dir / (name + "_" + what + ".npy"), a);
        };
        save("result", result.image);
        save("field", field);
        save("truth", scene.sim.ground_truth);
        save("alpha", result.alpha);
        save("true_alpha", scene.sim.alpha);
      }
    }
    std::fprintf(stderr, "%s\n", line.c_str());
    results.push_back({"ring_corrections", row, line});
  }
  nlohmann::json mean{{"scene", "mean"}, {"scenes", scenes}};
  std::string line = "mean:";
  for (std::size_t v = 0; v < totals.size(); ++v) {
    const Totals t{totals[v].psnr / scenes, totals[v].ssim / scenes,
                   totals[v].alpha_error / scenes};
    const std::string name = v < variants.size() ? variants[v].name : kReconstruct;
    mean[name] = {{"psnr", t.psnr}, {"ssim", t.ssim}, {"alpha_mae_live", t.alpha_error}};
    line += riner::bench::format("\n  %-42s %6.2f dB  SSIM %.3f  alpha error %.4f", name.c_str(),
                                 t.psnr, t.ssim, t.alpha_error);
  }
  results.push_back({"ring_corrections", mean, line});
  return results;
}

}  // namespace

RINER_BENCH_CASE(ring_corrections,
                 "ring corrections compared on the same trained fields (DeepLesion slices)",
                 ring_corrections);
