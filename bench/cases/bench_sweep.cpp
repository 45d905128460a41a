// Sweeps Riner's settings on the same ring scans and draws the Pareto front of PSNR against
// training time, from which the defaults are chosen. A sweep file names the variants:
//
//   {"base": {...config...},                        optional, applied to every variant
//    "variants": [{"name": "rays 160", "config": {"training": {"rays_per_step": 160}}},
//                 {"name": "...", "config": {...}, "device": "1"}, ...]}
//
// Each variant trains with checkpoints every --checkpoint steps; the learning-rate schedule
// depends on the step only, so the checkpoints of one run are also the runs with fewer steps.
//
//   riner_bench --case=sweep --sweep=bench/sweeps/defaults.json [--first=0] [--last=1]
//               [--checkpoint=1000] [--out=DIR] [--json=FILE]
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "harness.hpp"
#include "riner/metrics.hpp"
#include "riner/plot.hpp"
#include "riner/reconstructor.hpp"
#include "scenes.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

struct Point {
  std::string variant;
  int step = 0;
  double seconds = 0.0;  // mean over scenes
  double psnr = 0.0;     // mean over scenes
  double ssim = 0.0;
};

nlohmann::json read_sweep(const Options& o) {
  const std::string path = o.get("sweep", "bench/sweeps/defaults.json");
  std::ifstream f(path);
  if (!f) throw std::runtime_error("cannot read the sweep file " + path + " (--sweep=FILE)");
  nlohmann::json sweep = nlohmann::json::parse(f, nullptr, false);
  if (sweep.is_discarded() || !sweep.contains("variants") || !sweep["variants"].is_array())
    throw std::runtime_error(path + ": expected {\"variants\": [...]}");
  return sweep;
}

// Points not beaten by another point that is both faster and more accurate, by time.
std::vector<Point> pareto_front(std::vector<Point> points) {
  std::sort(points.begin(), points.end(), [](const Point& a, const Point& b) {
    return a.seconds < b.seconds || (a.seconds == b.seconds && a.psnr > b.psnr);
  });
  std::vector<Point> front;
  for (const Point& p : points) {
    if (front.empty() || p.psnr > front.back().psnr) front.push_back(p);
  }
  return front;
}

std::vector<Result> sweep(const Options& o) {
  const nlohmann::json sweep = read_sweep(o);
  const int first = o.get_int("first", 0);
  const int last = o.get_int("last", o.size == "tiny" ? first : 1);
  const int every = o.get_int("checkpoint", o.size == "tiny" ? 100 : 1000);
  const std::string out_dir = o.output_dir("out", "");
  const riner::RinerConfig defaults = riner::bench::config_from(o);

  std::vector<Result> results;
  std::vector<Point> all;
  riner::LinePlot plot;
  plot.x_label = "training time (s)";
  plot.y_label = "PSNR (dB)";
  const std::array<unsigned char, 3> palette[] = {
      {31, 119, 180}, {255, 127, 14},  {44, 160, 44},   {214, 39, 40},  {148, 103, 189},
      {140, 86, 75},  {227, 119, 194}, {127, 127, 127}, {188, 189, 34}, {23, 190, 207}};
  int variant_index = 0;
  for (const nlohmann::json& v : sweep["variants"]) {
    const std::string name = v.value("name", "variant " + std::to_string(variant_index));
    riner::RinerConfig config = defaults;
    if (sweep.contains("base")) config.update_from_json(sweep["base"].dump(), "sweep base");
    if (v.contains("config")) config.update_from_json(v["config"].dump(), name);
    if (o.size == "tiny") config.training.steps = std::min(config.training.steps_for(false), 200);
    config.validate();
    riner::Device device = riner::Device::open(v.value("device", o.device));
    const riner::Projector projector(riner::preset_geometry("fan2d-paper"), riner::Engine::kOpenCL,
                                     device);
    std::vector<Point> mean;
    int scenes = 0;
    for (int index = first; index <= last; ++index, ++scenes) {
      const riner::bench::RingScene scene = riner::bench::paper_scene(o, index, projector);
      riner::Reconstructor r(scene.sim.scan, config, device);
      nlohmann::json curve = nlohmann::json::array();
      std::size_t k = 0;
      const int steps = r.config().training.steps;
      while (r.steps_done() < steps) {
        r.step(std::min(every, steps - r.steps_done()));
        const riner::ImageMetrics m = riner::compare_images(r.image(), scene.sim.ground_truth);
        if (k == mean.size()) mean.push_back({name, r.steps_done(), 0.0, 0.0, 0.0});
        mean[k].seconds += r.stats().seconds;
        mean[k].psnr += m.psnr;
        mean[k].ssim += m.ssim;
        ++k;
        curve.push_back({{"step", r.steps_done()},
                         {"seconds", r.stats().seconds},
                         {"psnr", m.psnr},
                         {"ssim", m.ssim}});
      }
      std::fprintf(stderr, "sweep: %s on %s: %.2f dB in %.1f s\n", name.c_str(), scene.name.c_str(),
                   curve.back()["psnr"].get<double>(), r.stats().seconds);
      results.push_back(
          {"sweep",
           {{"variant", name},
            {"scene", scene.name},
            {"device", r.stats().device},
            {"samples_per_second", r.stats().samples / r.stats().seconds},
            {"curve", curve},
            {"config", nlohmann::json::parse(config.to_json())}},
           riner::bench::format("%-28s %-22s %6.2f dB  %7.1f s", name.c_str(), scene.name.c_str(),
                                curve.back()["psnr"].get<double>(), r.stats().seconds)});
    }
    riner::PlotSeries series;
    series.label = name;
    series.color = palette[variant_index % 10];
    nlohmann::json curve = nlohmann::json::array();
    for (Point& p : mean) {
      p.seconds /= scenes;
      p.psnr /= scenes;
      p.ssim /= scenes;
      series.x.push_back(p.seconds);
      series.y.push_back(p.psnr);
      curve.push_back(
          {{"step", p.step}, {"seconds", p.seconds}, {"psnr", p.psnr}, {"ssim", p.ssim}});
      all.push_back(p);
    }
    plot.series.push_back(series);
    results.push_back(
        {"sweep",
         {{"variant", name}, {"scene", "mean"}, {"scenes", scenes}, {"curve", curve}},
         riner::bench::format("%-28s %-22s %6.2f dB  %7.1f s  (SSIM %.3f)", name.c_str(), "mean",
                              mean.back().psnr, mean.back().seconds, mean.back().ssim)});
    ++variant_index;
  }

  const std::vector<Point> front = pareto_front(all);
  riner::PlotSeries front_series;
  front_series.label = "Pareto front";
  front_series.color = {0, 0, 0};
  front_series.points = true;
  nlohmann::json front_json = nlohmann::json::array();
  std::string text = "Pareto front (mean PSNR against mean training time):";
  for (const Point& p : front) {
    front_series.x.push_back(p.seconds);
    front_series.y.push_back(p.psnr);
    front_json.push_back({{"variant", p.variant},
                          {"step", p.step},
                          {"seconds", p.seconds},
                          {"psnr", p.psnr},
                          {"ssim", p.ssim}});
    text += riner::bench::format("\n  %7.1f s  %6.2f dB  SSIM %.3f  %s @ %d steps", p.seconds,
                                 p.psnr, p.ssim, p.variant.c_str(), p.step);
  }
  plot.series.push_back(front_series);
  results.push_back({"sweep", {{"pareto_front", front_json}}, text});
  if (!out_dir.empty()) {
    plot.title = "Sweep: mean over " + std::to_string(last - first + 1) + " scans";
    plot.width = 1100;
    plot.height = 560;
    const std::string path = out_dir + "/sweep_pareto.png";
    riner::write_plot_png(path, plot);
    std::fprintf(stderr, "wrote %s\n", path.c_str());
  }
  return results;
}

}  // namespace

RINER_BENCH_CASE(sweep, "settings sweep: Pareto front of PSNR against time (--sweep=FILE)", sweep);
