// The headline comparison: the same ring scans reconstructed by FBP, by Riner on the OpenCL
// engine and by Riner on the CPU reference engine, in one run, with PSNR, SSIM and the detector
// scores recorded against wall time at checkpoints. Writes a PSNR-vs-time plot with FBP as a
// horizontal line, and the seconds each engine needs to reach given PSNRs.
//
//   riner_bench --case=side_by_side [--first=0] [--last=9] [--checkpoint=250]
//               [--reference_seconds=120] [--targets=30,32,33] [--out=DIR] [--json=FILE]
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "harness.hpp"
#include "riner/fbp.hpp"
#include "riner/metrics.hpp"
#include "riner/plot.hpp"
#include "riner/reconstructor.hpp"
#include "scenes.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

struct Checkpoint {
  int step = 0;
  double seconds = 0.0;
  double psnr = 0.0;
  double ssim = 0.0;
  double field_psnr = 0.0;  // before the air-referenced ring correction
  double field_ssim = 0.0;
  nlohmann::json detector;
};

// Trains until the configured steps or until `budget_s` of training time, measuring every
// `every` steps (measurement time is not training time: stats().seconds counts step() only).
std::vector<Checkpoint> train(riner::Reconstructor& r, const riner::bench::RingScene& scene,
                              int every, double budget_s) {
  std::vector<Checkpoint> curve;
  const int total = r.config().training.steps;
  while (r.steps_done() < total && r.stats().seconds < budget_s) {
    r.step(std::min(every, total - r.steps_done()));
    const riner::ReconstructionResult result = r.result();
    const riner::ImageMetrics m = riner::compare_images(result.image, scene.sim.ground_truth);
    const riner::ImageMetrics f = riner::compare_images(result.field_image, scene.sim.ground_truth);
    curve.push_back({r.steps_done(), r.stats().seconds, m.psnr, m.ssim, f.psnr, f.ssim,
                     riner::bench::detector_accuracy(result.alpha, r.trained_beta(), scene.sim)});
  }
  return curve;
}

nlohmann::json to_json(const std::vector<Checkpoint>& curve) {
  nlohmann::json out = nlohmann::json::array();
  for (const Checkpoint& c : curve) {
    nlohmann::json point = {
        {"step", c.step}, {"seconds", c.seconds},       {"psnr", c.psnr},
        {"ssim", c.ssim}, {"field_psnr", c.field_psnr}, {"field_ssim", c.field_ssim}};
    for (const auto& [key, value] : c.detector.items()) {
      if (key != "dead") point[key] = value;  // the per-element details stay in the final row
    }
    out.push_back(point);
  }
  return out;
}

// A checkpoint's image metrics and position, as the result rows report them.
nlohmann::json checkpoint_metrics(const Checkpoint& c) {
  return {{"psnr", c.psnr},
          {"ssim", c.ssim},
          {"field_psnr", c.field_psnr},
          {"field_ssim", c.field_ssim},
          {"seconds", c.seconds},
          {"steps", c.step}};
}

// The mean curve over scenes, checkpoint by checkpoint, as far as every scene got.
std::vector<Checkpoint> mean_curve(const std::vector<std::vector<Checkpoint>>& curves) {
  std::vector<Checkpoint> mean;
  if (curves.empty()) return mean;
  std::size_t n = std::numeric_limits<std::size_t>::max();
  for (const auto& c : curves) n = std::min(n, c.size());
  for (std::size_t i = 0; i < n; ++i) {
    Checkpoint m;
    m.step = curves.front()[i].step;
    double alpha = 0.0;
    for (const auto& c : curves) {
      m.seconds += c[i].seconds / curves.size();
      m.psnr += c[i].psnr / curves.size();
      m.ssim += c[i].ssim / curves.size();
      m.field_psnr += c[i].field_psnr / curves.size();
      m.field_ssim += c[i].field_ssim / curves.size();
      alpha += c[i].detector["alpha_mae_live"].get<double>() / curves.size();
    }
    m.detector = {{"alpha_mae_live", alpha}};
    mean.push_back(m);
  }
  return mean;
}

// Seconds until the curve first reaches `psnr` (linear between checkpoints); NaN if never.
double seconds_to(const std::vector<Checkpoint>& curve, double psnr) {
  double t0 = 0.0, p0 = -std::numeric_limits<double>::infinity();
  for (const Checkpoint& c : curve) {
    if (c.psnr >= psnr) {
      if (!std::isfinite(p0)) return c.seconds;
      return t0 + (c.seconds - t0) * (psnr - p0) / (c.psnr - p0);
    }
    t0 = c.seconds;
    p0 = c.psnr;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

std::vector<Result> side_by_side(const Options& o) {
  const int first = o.get_int("first", 0);
  const int last = o.get_int("last", o.size == "tiny" ? first : 9);
  const int every = o.get_int("checkpoint", o.size == "tiny" ? 50 : 250);
  const double reference_budget = o.get_double("reference_seconds", o.size == "tiny" ? 5 : 120);
  const std::vector<double> targets = riner::bench::number_list(o.get("targets", "28,30,32,33,34"));
  const std::string out_dir = o.output_dir("out", "");
  riner::RinerConfig config = riner::bench::config_from(o);
  riner::Device device = riner::Device::open(o.device);
  const riner::Projector projector(riner::preset_geometry("fan2d-paper"), riner::Engine::kOpenCL,
                                   device);
  riner::FbpOptions fbp_options;
  fbp_options.device = device;

  std::vector<Result> results;
  struct EngineRun {
    std::string name;
    riner::Engine engine;
    double budget;
    std::vector<std::vector<Checkpoint>> curves;
    double samples_per_second = 0.0;
  };
  std::vector<EngineRun> engines = {
      {"opencl", riner::Engine::kOpenCL, std::numeric_limits<double>::infinity(), {}},
      {"reference", riner::Engine::kReference, reference_budget, {}}};
  if (reference_budget <= 0.0) engines.pop_back();
  double fbp_psnr = 0.0, fbp_ssim = 0.0, fbp_ms = 0.0;
  int scenes = 0;
  for (int index = first; index <= last; ++index, ++scenes) {
    const riner::bench::RingScene scene = riner::bench::paper_scene(o, index, projector);
    riner::Array fbp_image;
    const double ms =
        riner::bench::time_ms([&] { fbp_image = riner::fbp(scene.sim.scan, fbp_options); });
    const riner::ImageMetrics fbp = riner::compare_images(fbp_image, scene.sim.ground_truth);
    fbp_psnr += fbp.psnr;
    fbp_ssim += fbp.ssim;
    fbp_ms += ms;
    results.push_back(
        {"side_by_side",
         {{"scene", scene.name},
          {"engine", "fbp"},
          {"psnr", fbp.psnr},
          {"ssim", fbp.ssim},
          {"seconds", ms * 1e-3}},
         riner::bench::format("%-22s %-10s %8s %6.2f dB  SSIM %.3f  %7.2f s", scene.name.c_str(),
                              "fbp", "", fbp.psnr, fbp.ssim, ms * 1e-3)});
    for (EngineRun& e : engines) {
      config.engine = e.engine;
      riner::Reconstructor r(
          scene.sim.scan, config,
          e.engine == riner::Engine::kOpenCL ? std::optional(device) : std::nullopt);
      std::vector<Checkpoint> curve = train(r, scene, every, e.budget);
      const riner::TrainingStats st = r.stats();
      e.samples_per_second += st.samples / st.seconds;
      const Checkpoint& end = curve.back();
      nlohmann::json fields = {{"scene", scene.name},
                               {"engine", e.name},
                               {"device", st.device},
                               {"plan", st.plan ? st.plan->describe() : "reference"},
                               {"samples_per_second", st.samples / st.seconds},
                               {"detector", end.detector},
                               {"curve", to_json(curve)},
                               {"config", nlohmann::json::parse(config.to_json())}};
      fields.update(checkpoint_metrics(end));
      results.push_back({"side_by_side", fields,
                         riner::bench::format("%-22s %-10s %8d %6.2f dB  SSIM %.3f  (field %6.2f / "
                                              "%.3f)  %7.2f s  %.3g samples/s  "
                                              "alpha MAE %.4f  dead %d/%d  live off %d",
                                              scene.name.c_str(), e.name.c_str(), end.step,
                                              end.psnr, end.ssim, end.field_psnr, end.field_ssim,
                                              end.seconds, st.samples / st.seconds,
                                              end.detector["alpha_mae_live"].get<double>(),
                                              end.detector["dead_flagged"].get<int>(),
                                              end.detector["dead_crossing"].get<int>(),
                                              end.detector["live_switched_off"].get<int>())});
      std::fprintf(stderr, "%s, %s: %.2f dB at step %d, %.1f s\n", scene.name.c_str(),
                   e.name.c_str(), end.psnr, end.step, end.seconds);
      e.curves.push_back(std::move(curve));
    }
  }

  // Summary: mean curves, time to each target PSNR, and the plot.
  fbp_psnr /= scenes;
  fbp_ssim /= scenes;
  riner::LinePlot plot;
  plot.title = "Mean over " + std::to_string(scenes) + " ring scans (fan2d-paper)";
  plot.x_label = "training time (s)";
  plot.y_label = "PSNR (dB)";
  plot.horizontal_lines.push_back({fbp_psnr, riner::bench::format("FBP %.1f dB", fbp_psnr)});
  const std::array<std::array<unsigned char, 3>, 2> colors = {{{31, 119, 180}, {214, 39, 40}}};
  for (std::size_t i = 0; i < engines.size(); ++i) {
    const EngineRun& e = engines[i];
    const std::vector<Checkpoint> mean = mean_curve(e.curves);
    if (mean.empty()) continue;
    riner::PlotSeries series;
    series.label = e.name == "opencl" ? "OpenCL engine" : "reference engine (Eigen, double)";
    series.color = colors[i];
    nlohmann::json to_target = nlohmann::json::object();
    std::string target_text;
    for (double t : targets) {
      const double s = seconds_to(mean, t);
      to_target[riner::bench::format("%g", t)] =
          std::isnan(s) ? nlohmann::json() : nlohmann::json(s);
      target_text += std::isnan(s) ? riner::bench::format("  %g dB: -", t)
                                   : riner::bench::format("  %g dB: %.1f s", t, s);
    }
    for (const Checkpoint& c : mean) {
      series.x.push_back(c.seconds);
      series.y.push_back(c.psnr);
    }
    plot.series.push_back(series);
    const Checkpoint& end = mean.back();
    nlohmann::json fields = {{"scene", "mean"},
                             {"engine", e.name},
                             {"scenes", scenes},
                             {"alpha_mae_live", end.detector["alpha_mae_live"]},
                             {"samples_per_second", e.samples_per_second / scenes},
                             {"seconds_to_psnr", to_target},
                             {"curve", to_json(mean)}};
    fields.update(checkpoint_metrics(end));
    results.push_back({"side_by_side", fields,
                       riner::bench::format("%-22s %-10s %8d %6.2f dB  SSIM %.3f  (field %6.2f / "
                                            "%.3f)  %7.2f s  %.3g samples/s |%s",
                                            "mean", e.name.c_str(), end.step, end.psnr, end.ssim,
                                            end.field_psnr, end.field_ssim, end.seconds,
                                            e.samples_per_second / scenes, target_text.c_str())});
  }
  results.push_back({"side_by_side",
                     {{"scene", "mean"},
                      {"engine", "fbp"},
                      {"psnr", fbp_psnr},
                      {"ssim", fbp_ssim},
                      {"seconds", fbp_ms * 1e-3 / scenes}},
                     riner::bench::format("%-22s %-10s %8s %6.2f dB  SSIM %.3f  %7.2f s", "mean",
                                          "fbp", "", fbp_psnr, fbp_ssim, fbp_ms * 1e-3 / scenes)});
  if (!out_dir.empty()) {
    const std::string path = out_dir + "/side_by_side_psnr_time.png";
    riner::write_plot_png(path, plot);
    std::fprintf(stderr, "wrote %s\n", path.c_str());
  }
  return results;
}

}  // namespace

RINER_BENCH_CASE(side_by_side,
                 "FBP, OpenCL and reference engines on the same scans: PSNR against time, plot",
                 side_by_side);
