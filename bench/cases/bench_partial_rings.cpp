// Partial rings (issue 32): detector responses that change or die part-way through the scan, on
// the DeepLesion slices (the paper's responses and noise) in a 180-degree parallel beam, where
// no view has a twin that could stand in for a lost element. For each slice: FBP, Riner with
// training.partial_responses off (the defaults before it) and on, what the detection found
// against the truth, and the trained responses of the changing elements' segments.
//
//   riner_bench --case=partial_rings [--first=0] [--last=9] [--partial=12] [--partial_dead=4]
//               [--png=DIR] [--config=JSON] [--json=FILE]
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "harness.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/reconstructor.hpp"
#include "scenes.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

struct Detection {
  int changing = 0;              // elements whose true response changes
  int found = 0;                 // of those, found at their true view
  int misplaced = 0;             // found, at another view
  int extra = 0;                 // found, but unchanged
  double log_alpha_error = 0.0;  // mean |ln(alpha / truth)| over the found live segments
};

Detection score(const riner::Reconstructor& r, const riner::Array& alpha) {
  Detection d;
  const std::vector<riner::ChangingElement> found = r.changing_elements();
  const riner::Geometry& g = r.scan().geometry;
  const std::size_t elements = alpha.shape[1];
  int segments = 0;
  for (std::size_t e = 0; e < elements; ++e) {
    d.changing += !riner::response_change_views(alpha, g, e).empty();
  }
  for (const riner::ChangingElement& c : found) {
    const std::vector<std::size_t> truth = riner::response_change_views(alpha, g, c.element);
    if (truth.empty()) {
      ++d.extra;
      continue;
    }
    std::vector<std::size_t> starts;
    for (std::size_t i = 1; i < c.segments.size(); ++i) starts.push_back(c.segments[i].first_view);
    ++(starts == truth ? d.found : d.misplaced);
    for (const riner::ResponseSegment& s : c.segments) {
      const float a = alpha.data[s.first_view * elements + c.element];
      if (a == 0.0f) continue;
      d.log_alpha_error += std::fabs(std::log(s.alpha / a));
      ++segments;
    }
  }
  if (segments > 0) d.log_alpha_error /= segments;
  return d;
}

std::vector<Result> partial_rings(const Options& o) {
  const int first = o.get_int("first", 0);
  const int last = o.get_int("last", o.size == "tiny" ? first : 9);
  const std::string png_dir = o.output_dir("png", "");
  riner::Device device = riner::Device::open(o.device);
  // bench/partial_rings_geometry.json
  const riner::Projector projector(riner::bench::parallel_half_turn(), riner::Engine::kOpenCL,
                                   device);
  riner::RingModel model;
  model.partial_elements = static_cast<std::size_t>(o.get_int("partial", 12));
  model.partial_dead_elements = static_cast<std::size_t>(o.get_int("partial_dead", 4));
  riner::FbpOptions fbp_options;
  fbp_options.device = device;
  std::vector<Result> results;
  for (int slice = first; slice <= last; ++slice) {
    const riner::bench::RingScene scene = riner::bench::paper_scene(o, slice, projector, model);
    const riner::Array& truth = scene.sim.ground_truth;
    const riner::Array fbp_image = riner::fbp(scene.sim.scan, fbp_options);
    const riner::ImageMetrics fbp = riner::compare_images(fbp_image, truth);
    nlohmann::json fields = {{"scene", scene.name},
                             {"slice", slice},
                             {"partial", model.partial_elements},
                             {"partial_dead", model.partial_dead_elements},
                             {"fbp_psnr", fbp.psnr},
                             {"fbp_ssim", fbp.ssim}};
    std::vector<riner::Array> images;
    for (bool on : {false, true}) {
      riner::RinerConfig config = riner::bench::config_from(o);
      config.training.partial_responses = on;
      riner::Reconstructor r(scene.sim.scan, config, device);
      r.run();
      const riner::ReconstructionResult result = r.result();
      const riner::ImageMetrics m = riner::compare_images(result.image, truth);
      const std::string key = on ? "on" : "off";
      fields[key] = {{"psnr", m.psnr},
                     {"ssim", m.ssim},
                     {"edges", m.edge_ratio},
                     {"seconds", r.stats().seconds},
                     {"dead_elements", r.dead_elements().size()}};
      if (on) {
        const Detection d = score(r, scene.sim.alpha);
        fields["detection"] = {{"changing", d.changing},
                               {"found_at_their_view", d.found},
                               {"found_elsewhere", d.misplaced},
                               {"found_unchanged", d.extra},
                               {"mean_abs_log_alpha_error", d.log_alpha_error}};
        std::fprintf(stderr,
                     "%s: FBP %.2f, off %.2f / %.4f, on %.2f / %.4f; changes %d, found %d "
                     "(elsewhere %d, unchanged %d), |ln alpha err| %.4f\n",
                     scene.name.c_str(), fbp.psnr, fields["off"]["psnr"].get<double>(),
                     fields["off"]["ssim"].get<double>(), m.psnr, m.ssim, d.changing, d.found,
                     d.misplaced, d.extra, d.log_alpha_error);
      }
      images.push_back(result.image);
    }
    if (!png_dir.empty()) {
      // truth | FBP | Riner, partial_responses off | on
      riner::bench::write_panel_png(
          png_dir + "/partial_rings_slice" + std::to_string(slice) + ".png",
          {&truth, &fbp_image, &images[0], &images[1]}, riner::Window{0.0f, 0.035f});
    }
    results.push_back({"partial_rings", fields});
  }
  return results;
}

}  // namespace

RINER_BENCH_CASE(partial_rings,
                 "partial rings: responses changing or dying part-way, Riner with and without "
                 "partial_responses (DeepLesion, 180-degree parallel beam)",
                 partial_rings);
