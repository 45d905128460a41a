// Ring-correction chains replayed on saved training results: train once, then try orders and
// settings of the corrections in seconds instead of retraining (docs/history/RESULTS.md, issue 13).
//
//   riner_bench --case=ring_chain_replay --save=DIR [--first=0] [--last=9] [--seed-offset=0]
//   riner_bench --case=ring_chain_replay --save=DIR --scan=SINO.npy --tag=NAME [--seed=N]
//       train at the config and save, per scan, DIR/NAME/: the field, the trained alpha, the
//       dead elements, the geometry, the reference (DeepLesion: the ground truth; a real scan:
//       its FBP) and which pixels the reconstruction zeroed as skipped air
//   riner_bench --case=ring_chain_replay --replay=DIR [--order=agrg] [--config=JSON] [--json=F]
//       [--images=OUT] (each result as OUT/SCAN_ORDER.npy) [--verbose=1] (what each step did)
//       run the corrections in `order` (a = air, g = radial gradient, r = detector response,
//       m = mirror pairs; the default is the reconstruction's chain) on every saved scan;
//       DeepLesion: PSNR / SSIM against the truth, real scans: the quality report against FBP
#include <algorithm>
#include <cstdio>
#include <filesystem>

#include "harness.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/quality.hpp"
#include "riner/reconstructor.hpp"
#include "riner/ring_chain.hpp"
#include "riner/ring_correction.hpp"
#include "riner/scan.hpp"
#include "saved_training.hpp"
#include "scenes.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;
namespace fs = std::filesystem;

constexpr const char* kChain = "magrg";  // --order's default: riner::correct_rings_in_order's

using Saved = riner::bench::SavedTraining;

// What a step did, on one line (--verbose): whether it applied, what it moved.
void describe(char step, const riner::RingCorrection& r) {
  double lowest = 0.0, highest = 0.0;
  if (!r.object_radii_mm.empty()) {
    const auto [lo, hi] = std::minmax_element(r.object_radii_mm.begin(), r.object_radii_mm.end());
    lowest = *lo;
    highest = *hi;
  }
  std::printf(
      "  %c: applied %d, mean |change of ln alpha| %.4g, radii measured %zu, kept %zu, "
      "elements moved %zu (largest %.1f sigmas), objects %zu at %.1f-%.1f mm, even/odd %.2f\n",
      step, r.applied ? 1 : 0, r.mean_response_change, r.measured_radii, r.radii_kept_for_objects,
      r.elements_moved, r.largest_even_sigmas, r.object_radii_mm.size(), lowest, highest,
      r.even_to_odd);
}

riner::Array replay(const std::string& order, const Saved& s, const riner::RingCorrectionConfig& c,
                    bool verbose) {
  riner::Array image = s.field;
  riner::Array alpha = s.alpha;
  std::vector<double> objects;  // the mirror pairs' objects, as riner::correct_rings_in_order
  for (char step : order) {
    riner::RingCorrection r;
    if (step == 'a') {
      r = riner::correct_rings_from_air(image, alpha, s.geometry, c.air);
    } else if (step == 'g') {
      r = riner::correct_rings_from_gradient(image, alpha, s.geometry, c.gradient, objects);
    } else if (step == 'r') {
      r = riner::correct_rings_from_response(image, alpha, s.geometry, s.dead, c.response, objects);
    } else if (step == 'm') {
      r = riner::correct_rings_from_mirrors(image, alpha, s.geometry, s.dead, c.mirror);
      objects = r.object_radii_mm;
    } else {
      throw riner::InputError(std::string("--order: unknown step '") + step + "' (a, g, r or m)");
    }
    if (verbose) describe(step, r);
    image = std::move(r.image);
    alpha = std::move(r.alpha);
    // As riner::correct_rings_in_order: the skipped air back to 0 before the next step.
    for (std::size_t p = 0; p < image.size(); ++p) image.data[p] *= s.keep.data[p];
  }
  return image;
}

std::vector<Result> ring_chain_replay(const Options& o) {
  riner::RinerConfig config = riner::bench::config_from(o);
  if (o.size == "tiny") config.training.steps = std::min(config.training.steps_for(false), 200);
  const std::string save_dir = o.get("save", "");
  const std::string replay_dir = o.get("replay", "");
  if (save_dir.empty() == replay_dir.empty()) {
    throw riner::InputError("ring_chain_replay: give --save=DIR or --replay=DIR");
  }
  std::vector<Result> results;
  if (!save_dir.empty()) {
    riner::Device device = riner::Device::open(o.device);
    const std::string scan_path = o.get("scan", "");
    if (scan_path.empty()) {
      const riner::Projector projector(riner::preset_geometry("fan2d-paper"),
                                       riner::Engine::kOpenCL, device);
      for (int i = o.get_int("first", 0); i <= o.get_int("last", 9); ++i) {
        const riner::bench::RingScene scene = riner::bench::paper_scene(o, i, projector);
        riner::Reconstructor r(scene.sim.scan, config, device);
        r.run();
        const std::string name = "slice_" + std::to_string(i + o.get_int("seed-offset", 0));
        riner::bench::save_training(fs::path(save_dir) / name, r, scene.sim.scan.geometry,
                                    scene.sim.ground_truth, true, config.rings);
        std::fprintf(stderr, "%s: saved after %.1f s of training\n", name.c_str(),
                     r.stats().seconds);
      }
    } else {
      const riner::Scan scan = riner::load_scan(scan_path);
      riner::FbpOptions fbp_options;
      fbp_options.device = device;
      const riner::Array fbp_image = riner::fbp(scan, fbp_options);
      riner::Reconstructor r(scan, config, device);
      r.run();
      riner::bench::save_training(fs::path(save_dir) / o.get("tag", "scan"), r, scan.geometry,
                                  fbp_image, false, config.rings);
    }
    return results;
  }
  const std::string order = o.get("order", kChain);
  const std::string images_dir = o.get("images", "");
  if (!images_dir.empty()) fs::create_directories(images_dir);
  std::vector<fs::path> dirs;
  for (const auto& entry : fs::directory_iterator(replay_dir)) {
    if (entry.is_directory()) dirs.push_back(entry.path());
  }
  std::sort(dirs.begin(), dirs.end());
  double psnr = 0.0, ssim = 0.0;
  int simulated = 0;
  for (const fs::path& dir : dirs) {
    const Saved s = riner::bench::load_training(dir);
    const riner::Array image = replay(order, s, config.rings, o.get_int("verbose", 0) != 0);
    const std::string name = dir.filename().string();
    if (!images_dir.empty()) {
      riner::write_array(fs::path(images_dir) / (name + "_" + order + ".npy"), image);
    }
    nlohmann::json row{{"scan", name}, {"order", order}};
    std::string line;
    if (s.simulated) {
      const riner::ImageMetrics m = riner::compare_images(image, s.reference);
      psnr += m.psnr;
      ssim += m.ssim;
      ++simulated;
      row["psnr"] = m.psnr;
      row["ssim"] = m.ssim;
      line = riner::bench::format("%-12s %s  %.3f dB / %.4f", name.c_str(), order.c_str(), m.psnr,
                                  m.ssim);
    } else {
      const riner::QualityReport q =
          riner::quality_against_fbp(image, s.reference, riner::field_radius_px(s.geometry));
      row.update({{"ring_index", q.ring_index},
                  {"fbp_ring_index", q.fbp_ring_index},
                  {"specks_per_10k", q.specks_per_10k},
                  {"fbp_specks_per_10k", q.fbp_specks_per_10k},
                  {"centre_sigmas", q.centre.sigmas},
                  {"edge_ratio", q.edge_strength / q.fbp_edge_strength},
                  {"lost_object_share", q.lost.share}});
      line = riner::bench::format(
          "%-12s %s  ring %.5f (FBP/3 %.5f)  specks %.3f (FBP %.3f)  centre %.2f sigma  edges "
          "%.3f of FBP's  lost %.4f%%",
          name.c_str(), order.c_str(), q.ring_index, q.fbp_ring_index / 3, q.specks_per_10k,
          q.fbp_specks_per_10k, q.centre.sigmas, q.edge_strength / q.fbp_edge_strength,
          100 * q.lost.share);
    }
    std::fprintf(stderr, "%s\n", line.c_str());
    results.push_back({"ring_chain_replay", row, line});
  }
  if (simulated > 0) {
    const nlohmann::json mean{{"scan", "simulated mean"},
                              {"order", order},
                              {"scans", simulated},
                              {"psnr", psnr / simulated},
                              {"ssim", ssim / simulated}};
    results.push_back({"ring_chain_replay", mean,
                       riner::bench::format("mean of %d simulated: %.3f dB / %.4f", simulated,
                                            psnr / simulated, ssim / simulated)});
  }
  return results;
}

}  // namespace

RINER_BENCH_CASE(ring_chain_replay,
                 "ring-correction chains replayed on saved training results (--save, --replay)",
                 ring_chain_replay);
