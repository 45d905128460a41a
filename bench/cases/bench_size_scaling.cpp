// riner at the sizes users scan (issue 29 item 2): the paper's fan-beam protocol with the
// detector resampled to each of --columns (the paper's 1 m detector at C elements, 360 C / 512
// views over 360 degrees, the grid C/2 square over the same 256 mm), riner at the settings
// against the truth beside the FBP of the same scan and of its twin with a perfect detector
// (the oracle): PSNR, SSIM, the edges' sharpness against the truth (ImageMetrics::edge_ratio),
// the training time, how often each ray is drawn and the elements beta switched off.
//
//   riner_bench --case=size_scaling [--columns=512,1024,2048] [--scene=deeplesion|shepp-logan]
//               [--first=3 --last=3] [--seed-offset=N] [--config=JSON] [--json=FILE]
//               [--images=DIR] [--save=DIR]
// --images: the truth, riner's image, the oracle FBP, the learned and the true alpha, the trained
// field and the image after each ring correction as .npy per scene and size, for looking at
// where the error lies. --save: each trained result as DIR/SCENE_INDEX_COLUMNS/ for replaying the
// ring corrections on it (ring_chain_replay --replay=DIR).
// deeplesion: the shared slices (1 mm pixels) resampled bilinearly: no detail finer than 1 mm at
// any size. shepp-logan: rasterised on each grid (4x supersampled): sharp at every size.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>
#include <utility>

#include "harness.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/phantom.hpp"
#include "riner/projector.hpp"
#include "riner/reconstructor.hpp"
#include "riner/resample.hpp"
#include "riner/simulate.hpp"
#include "saved_training.hpp"
#include "scenes.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

constexpr double kDetectorMm = 1000.0;
constexpr double kFieldMm = 256.0;
constexpr std::size_t kPaperColumns = 512;
constexpr std::size_t kPaperViews = 360;

std::vector<std::size_t> columns_from(const std::string& text) {
  std::vector<std::size_t> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    const long c = std::strtol(item.c_str(), &end, 10);
    if (end == item.c_str() || *end != '\0' || c < 64 || c % 2 != 0)
      throw riner::InputError(
          "--columns takes even counts of at least 64, separated by commas "
          "(got '" +
          item + "')");
    out.push_back(static_cast<std::size_t>(c));
  }
  return out;
}

riner::Geometry sized_geometry(std::size_t columns) {
  riner::Geometry g;
  g.type = riner::GeometryType::kFan2d;
  g.n_u = columns;
  g.pitch_u = kDetectorMm / static_cast<double>(columns);
  g.source_origin_mm = 370.0;
  g.origin_detector_mm = 370.0;
  const riner::UniformAngles angles{kPaperViews * columns / kPaperColumns, 0.0, 2.0 * M_PI};
  g.uniform_angles = angles;
  g.angles = riner::uniform_angles(angles);
  g.volume_shape = {columns / 2, columns / 2};
  g.voxel_mm = kFieldMm / static_cast<double>(columns / 2);
  g.validate();
  return g;
}

riner::Array truth_on(const riner::Geometry& g, const std::string& scene, int index,
                      const Options& o) {
  if (scene == "shepp-logan") return riner::rasterize(riner::shepp_logan(g, 0.02), g, 4);
  if (scene != "deeplesion")
    throw riner::InputError("--scene is deeplesion or shepp-logan (got '" + scene + "')");
  const std::string path =
      o.get("data", "../shared/data/deeplesion") + "/slice_" + std::to_string(index) + ".nii";
  riner::Array slice = riner::read_array(path).array;
  for (float& v : slice.data) v *= 0.1f;  // 1/cm -> 1/mm (METHOD.md section 4)
  return riner::resample_to_grid(slice, {1.0, 1.0}, g);
}

std::vector<Result> size_scaling(const Options& o) {
  const std::vector<std::size_t> columns = columns_from(o.get("columns", "512,1024,2048"));
  const std::string scene = o.get("scene", "deeplesion");
  const int first = o.get_int("first", 3);
  const int last = o.get_int("last", first);
  const riner::RinerConfig config = riner::bench::config_from(o);
  riner::Device device = riner::Device::open(o.device);
  riner::FbpOptions fbp_options;
  fbp_options.device = device;
  std::vector<Result> rows;
  for (int index = first; index <= last; ++index) {
    for (std::size_t c : columns) {
      const riner::Geometry g = sized_geometry(c);
      const riner::Projector projector(g, riner::Engine::kOpenCL, device);
      const riner::Array truth = truth_on(g, scene, index, o);
      riner::RingModel model;
      model.seed = static_cast<std::uint64_t>(index + o.get_int("seed-offset", 0));
      const riner::SimulatedScan sim = riner::simulate(truth, projector, model);
      riner::RingModel perfect = model;
      perfect.nonideal_fraction = 0.0;
      perfect.dead_elements = 0;
      const riner::SimulatedScan twin = riner::simulate(truth, projector, perfect);
      const riner::ImageMetrics fbp =
          riner::compare_images(riner::fbp(sim.scan, fbp_options), truth);
      const riner::Array oracle_image = riner::fbp(twin.scan, fbp_options);
      const riner::ImageMetrics oracle = riner::compare_images(oracle_image, truth);

      riner::Reconstructor r(sim.scan, config, device);
      r.run();
      const riner::ImageMetrics m = riner::compare_images(r.result().image, truth);
      const riner::TrainingStats st = r.stats();
      const int rays_per_step = st.rays_per_step;
      const double draws_per_ray =
          static_cast<double>(st.steps) * rays_per_step / static_cast<double>(g.n_views() * g.n_u);
      // beta below 0.5 on a live element takes its rays out of training: at size it was the
      // first sign of a loose fit (docs/history/RESULTS.md, issue 29).
      const riner::Array beta = r.trained_beta();
      int live_off = 0, dead_found = 0, dead = 0;
      for (std::size_t e = 0; e < beta.size(); ++e) {
        const bool is_dead = sim.alpha.data[e] == 0.0f;
        dead += is_dead;
        if (beta.data[e] < riner::Reconstructor::kDeadBelowBeta)
          (is_dead ? dead_found : live_off) += 1;
      }
      const std::string name = scene + "/" + std::to_string(index);
      const riner::ResidualDetail detail = r.result().residual_detail;
      if (const std::string dir = o.get("save", ""); !dir.empty()) {
        riner::bench::save_training(
            std::filesystem::path(dir) /
                (scene + "_" + std::to_string(index) + "_" + std::to_string(c)),
            r, g, truth, true, config.rings);
      }
      if (const std::string dir = o.get("images", ""); !dir.empty()) {
        const std::filesystem::path stem =
            std::filesystem::path(dir) /
            (scene + "_" + std::to_string(index) + "_" + std::to_string(c) + "_");
        std::filesystem::create_directories(dir);
        const riner::ReconstructionResult res = r.result();
        riner::write_array(stem.string() + "truth.npy", truth);
        riner::write_array(stem.string() + "riner.npy", res.image);
        riner::write_array(stem.string() + "oracle.npy", oracle_image);
        riner::write_array(stem.string() + "alpha.npy", res.alpha);
        riner::write_array(stem.string() + "alpha_true.npy", sim.alpha);
        riner::write_array(stem.string() + "field.npy", res.field_image);
        // Each ring correction's image as it gave it (before the skipped air is set back to 0),
        // in the chain's order, and what it did.
        const std::pair<const char*, const std::optional<riner::RingCorrection>*> steps[] = {
            {"mirror", &res.mirror_rings},
            {"air", &res.air_rings},
            {"gradient", &res.gradient_rings},
            {"response", &res.response_rings},
            {"gradient_again", &res.gradient_after_response_rings},
            {"gradient_after_detail", &res.gradient_after_detail_rings}};
        for (const auto& [step, correction] : steps) {
          if (!correction->has_value()) continue;
          const riner::RingCorrection& step_result = **correction;
          riner::write_array(stem.string() + "after_" + step + ".npy", step_result.image);
          std::fprintf(stderr,
                       "  %s: applied %d, mean response change %.5f, even/odd %.2f, scale %.1f px\n",
                       step, step_result.applied ? 1 : 0, step_result.mean_response_change,
                       step_result.even_to_odd, step_result.scale_px);
        }
        std::fprintf(stderr,
                     "  detail: applied %d, consistent share %.3f, held-out misfit %.6g -> %.6g\n",
                     res.residual_detail.applied ? 1 : 0, res.residual_detail.consistent_share,
                     res.residual_detail.misfit_before, res.residual_detail.misfit_after);
      }
      rows.push_back(
          {"size_scaling",
           {{"scene", name},
            {"columns", c},
            {"grid", g.volume_shape[0]},
            {"views", g.n_views()},
            {"psnr", m.psnr},
            {"ssim", m.ssim},
            {"edge_ratio", m.edge_ratio},
            {"oracle_psnr", oracle.psnr},
            {"oracle_ssim", oracle.ssim},
            {"oracle_edge_ratio", oracle.edge_ratio},
            {"fbp_psnr", fbp.psnr},
            {"seconds", st.seconds},
            {"steps", st.steps},
            {"rays_per_step", rays_per_step},
            {"draws_per_ray", draws_per_ray},
            {"live_elements_off", live_off},
            {"dead_elements_found", dead_found},
            {"dead_elements", dead},
            {"residual_detail_applied", detail.applied},
            {"residual_detail_misfit", {detail.misfit_before, detail.misfit_after}},
            {"config", nlohmann::json::parse(config.to_json())}},
           riner::bench::format("%s %5zu columns (%4zu^2, %4zu views): riner %.2f dB / %.3f, "
                                "edges %.3f | oracle %.2f / %.3f, edges %.3f | FBP %.2f | "
                                "%.1f s, %.1f draws per ray, %d live off, %d/%d dead found",
                                name.c_str(), c, g.volume_shape[0], g.n_views(), m.psnr, m.ssim,
                                m.edge_ratio, oracle.psnr, oracle.ssim, oracle.edge_ratio, fbp.psnr,
                                st.seconds, draws_per_ray, live_off, dead_found, dead)});
    }
  }
  return rows;
}

}  // namespace

RINER_BENCH_CASE(size_scaling, "riner at 512-2048 columns against the oracle FBP and the truth",
                 size_scaling);
