// Riner end to end: the paper protocol on the DeepLesion slices (accuracy and run time, with
// FBP beside it), a parallel-beam Shepp-Logan ring scan, and the real neutron scan.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "harness.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/phantom.hpp"
#include "riner/quality.hpp"
#include "riner/reconstructor.hpp"
#include "riner/scan.hpp"
#include "riner/simulate.hpp"
#include "scenes.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

// Trains with metric checkpoints every `every` steps; returns the final metrics.
nlohmann::json train_and_measure(riner::Reconstructor& r, const riner::Array& truth, int every,
                                 std::vector<nlohmann::json>* curve) {
  const int total = r.config().training.steps;
  while (r.steps_done() < total) {
    r.step(std::min(every, total - r.steps_done()));
    const riner::ImageMetrics m = riner::compare_images(r.image(), truth);
    curve->push_back({{"step", r.steps_done()},
                      {"seconds", r.stats().seconds},
                      {"psnr", m.psnr},
                      {"ssim", m.ssim}});
  }
  return curve->empty() ? nlohmann::json() : curve->back();
}

std::vector<Result> riner_deeplesion(const Options& o) {
  const int first = o.get_int("first", 0);
  const int last = o.get_int("last", o.size == "tiny" ? first : 9);
  const int every = o.get_int("checkpoint", 1000);
  const std::string png_dir = o.output_dir("png", "");
  const riner::RinerConfig config = riner::bench::config_from(o);
  riner::Device device = riner::Device::open(o.device);
  const riner::Projector projector(riner::preset_geometry("fan2d-paper"), riner::Engine::kOpenCL,
                                   device);
  riner::FbpOptions fbp_options;
  fbp_options.device = device;
  std::vector<Result> results;
  for (int slice = first; slice <= last; ++slice) {
    const riner::bench::RingScene scene = riner::bench::paper_scene(o, slice, projector);
    const riner::Array& truth = scene.sim.ground_truth;
    const riner::Array fbp_image = riner::fbp(scene.sim.scan, fbp_options);
    const riner::ImageMetrics fbp = riner::compare_images(fbp_image, truth);

    riner::Reconstructor r(scene.sim.scan, config,
                           config.engine == riner::Engine::kOpenCL
                               ? std::optional<riner::Device>(device)
                               : std::nullopt);
    std::vector<nlohmann::json> curve;
    train_and_measure(r, truth, every, &curve);
    const riner::ReconstructionResult result = r.result();
    const riner::Array& image = result.image;
    const riner::Array& field = result.field_image;
    const riner::ImageMetrics m = riner::compare_images(image, truth);
    const riner::TrainingStats st = r.stats();
    const riner::ImageMetrics fm = riner::compare_images(field, truth);
    if (!png_dir.empty()) {
      // truth | FBP | the trained field | Riner (after the air-referenced ring correction)
      const std::size_t n = truth.shape[0];
      riner::Array panel({n, 4 * n});
      for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t k = 0; k < n; ++k) {
          panel(i, k) = truth(i, k);
          panel(i, n + k) = fbp_image(i, k);
          panel(i, 2 * n + k) = field(i, k);
          panel(i, 3 * n + k) = image(i, k);
        }
      }
      riner::write_png(png_dir + "/deeplesion_slice" + std::to_string(slice) + ".png", panel,
                       riner::Window{0.0f, 0.035f});
    }
    nlohmann::json fields = riner::bench::detector_accuracy(result.alpha, r.trained_beta(),
                                                            scene.sim, r.dead_elements());
    fields.update({{"scene", scene.name},
                   {"slice", slice},
                   {"psnr", m.psnr},
                   {"ssim", m.ssim},
                   {"field_psnr", fm.psnr},
                   {"field_ssim", fm.ssim},
                   {"fbp_psnr", fbp.psnr},
                   {"fbp_ssim", fbp.ssim},
                   {"seconds", st.seconds},
                   {"steps", st.steps},
                   {"samples_per_second", st.samples / st.seconds},
                   {"engine", st.engine},
                   {"curve", curve},
                   {"config", nlohmann::json::parse(config.to_json())}});
    results.push_back({"riner_deeplesion", fields});
    std::fprintf(stderr, "%s: PSNR %.2f SSIM %.4f (field %.2f / %.4f, FBP %.2f) in %.1fs\n",
                 scene.name.c_str(), m.psnr, m.ssim, fm.psnr, fm.ssim, fbp.psnr, st.seconds);
  }
  return results;
}

// A parallel-beam Shepp-Logan ring scan (180 degrees, off-centre axis).
std::vector<Result> riner_parallel_shepp_logan(const Options& o) {
  const riner::Geometry g = riner::bench::parallel_half_turn(3.5);
  const riner::Phantom phantom = riner::shepp_logan(g);
  const riner::Array truth = riner::rasterize(phantom, g, 4);
  riner::RingModel model;
  model.seed = 7;
  riner::Scan scan{{}, g, 0};
  const riner::Array clean = riner::exact_projections(phantom, g);
  const riner::Array alpha = riner::draw_responses(g, model);
  scan.measurement = riner::corrupt_measurement(clean, alpha, model);
  scan.non_finite = riner::compute_stats(scan.measurement).non_finite();
  riner::FbpOptions fbp_options;
  fbp_options.device = riner::Device::open(o.device);
  const riner::ImageMetrics fbp = riner::compare_images(riner::fbp(scan, fbp_options), truth);
  const riner::RinerConfig config = riner::bench::config_from(o);
  riner::Reconstructor r(scan, config, fbp_options.device);
  std::vector<nlohmann::json> curve;
  train_and_measure(r, truth, o.get_int("checkpoint", 2000), &curve);
  const riner::ReconstructionResult result = r.result();
  const riner::ImageMetrics m = riner::compare_images(result.image, truth);
  const riner::ImageMetrics field = riner::compare_images(result.field_image, truth);
  std::fprintf(stderr, "parallel Shepp-Logan: PSNR %.2f SSIM %.4f (field %.2f / %.4f; FBP %.2f)\n",
               m.psnr, m.ssim, field.psnr, field.ssim, fbp.psnr);
  return {{"riner_parallel_shepp_logan",
           {{"psnr", m.psnr},
            {"ssim", m.ssim},
            {"field_psnr", field.psnr},
            {"field_ssim", field.ssim},
            {"fbp_psnr", fbp.psnr},
            {"fbp_ssim", fbp.ssim},
            {"seconds", r.stats().seconds},
            {"curve", curve}}}};
}

}  // namespace

RINER_BENCH_CASE(riner_deeplesion, "Riner vs FBP on the paper protocol (DeepLesion slices)",
                 riner_deeplesion);
RINER_BENCH_CASE(riner_parallel_shepp_logan, "Riner on a parallel-beam Shepp-Logan ring scan",
                 riner_parallel_shepp_logan);

namespace {

// Two images of the same shape side by side.
riner::Array beside(const riner::Array& left, const riner::Array& right) {
  const std::size_t ny = left.shape[0], nx = left.shape[1];
  riner::Array panel({ny, 2 * nx});
  for (std::size_t i = 0; i < ny; ++i) {
    for (std::size_t k = 0; k < nx; ++k) {
      panel(i, k) = left(i, k);
      panel(i, nx + k) = right(i, k);
    }
  }
  return panel;
}

// One seed's run of riner_real_scan: Riner against the scan's FBP; PNG pairs and .npy files
// when `png` / `npy` name a prefix.
nlohmann::json real_scan_run(const riner::Scan& scan, const riner::Array& fbp_image,
                             const riner::RinerConfig& config, const riner::Device& device,
                             const std::string& png, const std::string& npy) {
  riner::Reconstructor r(scan, config, device);
  r.run();
  const riner::ReconstructionResult result = r.result();
  const riner::Array& field = result.field_image;
  const riner::Array& image = result.image;
  const std::optional<riner::RingCorrection>& rings = result.air_rings;
  const std::optional<riner::RingCorrection>& gradient = result.gradient_rings;
  const std::optional<riner::RingCorrection>& response = result.response_rings;
  const std::optional<riner::RingCorrection>& again = result.gradient_after_response_rings;
  const std::optional<riner::RingCorrection>& after_detail = result.gradient_after_detail_rings;
  const bool corrected = (rings && rings->applied) || (gradient && gradient->applied) ||
                         (response && response->applied) || (again && again->applied) ||
                         (after_detail && after_detail->applied);
  const riner::Array beta = r.trained_beta();
  int off = 0;
  for (float b : beta.data) off += b < 0.5f;
  if (!png.empty()) {
    // FBP | Riner at the same window (FBP's percentiles), then the central quarter enlarged.
    const std::size_t ny = image.shape[0], nx = image.shape[1];
    const riner::Window w = riner::percentile_window(fbp_image, 1.0, 99.5);
    riner::write_png(png + "_fbp_riner.png", beside(fbp_image, image), w);
    if (corrected) {
      // The trained field | after the ring corrections, a narrow window on the air.
      riner::write_png(png + "_field_corrected.png", beside(field, image),
                       riner::percentile_window(field, 1.0, 90.0));
    }
    const std::size_t h = ny / 4, c0 = ny / 2 - h / 2, c1 = nx / 2 - h / 2;
    riner::Array zoom({2 * h, 4 * h});
    for (std::size_t i = 0; i < 2 * h; ++i) {
      for (std::size_t k = 0; k < 4 * h; ++k) {
        const riner::Array& src = k < 2 * h ? fbp_image : image;
        zoom(i, k) = src(c0 + i / 2, c1 + (k % (2 * h)) / 2);
      }
    }
    riner::write_png(png + "_fbp_riner_centre.png", zoom, w);
  }
  const riner::QualityReport quality =
      riner::quality_against_fbp(image, fbp_image, riner::field_radius_px(scan.geometry));
  if (!npy.empty()) {  // the images, for analysis
    riner::write_array(npy + "_fbp.npy", fbp_image);
    riner::write_array(npy + "_field.npy", field);
    riner::write_array(npy + "_image.npy", image);
    riner::write_array(npy + "_alpha.npy", result.alpha);
    riner::write_array(npy + "_trained_alpha.npy", r.trained_alpha());
  }
  return {{"seed", config.training.seed},
          {"fbp_ring_index", riner::ring_index(fbp_image)},
          {"riner_ring_index", riner::ring_index(image)},
          {"noise", quality.noise},
          {"fbp_specks_per_10k", quality.fbp_specks_per_10k},
          {"riner_specks_per_10k", quality.specks_per_10k},
          {"field_specks_per_10k", riner::specks_per_10k(field, quality.noise)},
          {"fbp_edge_strength", quality.fbp_edge_strength},
          {"riner_edge_strength", quality.edge_strength},
          {"edge_ratio", quality.edge_strength / quality.fbp_edge_strength},
          {"edge_scale_px", quality.edge_scale_px},
          {"lost_object_pixels", quality.lost.pixels},
          {"lost_object_share", quality.lost.share},
          {"centre_deviation", quality.centre.deviation},
          {"centre_deviation_at_px", quality.centre.at_px},
          {"centre_deviation_sigmas", quality.centre.sigmas},
          {"centre_fbp_profile_noise", quality.centre.fbp_noise},
          {"field_centre_deviation_sigmas", riner::centre_deviation(field, fbp_image).sigmas},
          {"samples_kept_fraction", r.stats().samples_kept_fraction},
          {"grid_fraction_sampled", r.stats().inside_fraction},
          {"field_ring_index", riner::ring_index(field)},
          {"ring_correction_applied", rings && rings->applied},
          {"ring_correction_response_change", rings ? rings->mean_response_change : 0.0},
          {"gradient_correction_applied", gradient && gradient->applied},
          {"gradient_correction_response_change", gradient ? gradient->mean_response_change : 0.0},
          {"response_correction_applied", response && response->applied},
          {"response_correction_response_change", response ? response->mean_response_change : 0.0},
          {"gradient_after_response_applied", again && again->applied},
          {"gradient_after_detail_applied", after_detail && after_detail->applied},
          {"gradient_after_detail_response_change",
           after_detail ? after_detail->mean_response_change : 0.0},
          {"response_correction_even_to_odd",
           response && std::isfinite(response->even_to_odd) ? response->even_to_odd : 1e9},
          {"elements_switched_off", off},
          {"residual_detail_applied", result.residual_detail.applied},
          {"residual_detail_consistent_share", result.residual_detail.consistent_share},
          {"residual_detail_misfit",
           {result.residual_detail.misfit_before, result.residual_detail.misfit_after}},
          {"seconds", r.stats().seconds},
          {"steps", r.stats().steps}};
}

// A real scan (neutron360 by default): FBP and Riner side by side, ring index, specks and the
// centre's deviation from FBP (riner/quality.hpp) of each; --png=PREFIX for the PNG pairs,
// --npy=PREFIX for the images and responses as .npy (both of the first seed). --seeds=N runs
// seeds s .. s + N - 1 (s: --seed=N or the config's, 0 by default), one row each, and a row
// counting how many pass each of issue 13's bars: ring index <= FBP's / 3, specks <= FBP's, centre
// <= 1 sigma (one seed's numbers can pass a bar another's fails: docs/history/RESULTS.md), how many
// keep their edges (edge strength >= 0.8 of FBP's: a blur passes the other bars) and how many
// lose no object (issue 29: quality.lost_object 0).
std::vector<Result> riner_real_scan(const Options& o) {
  const std::string scan_path = o.get("scan", "../shared/data/neutron360/sino.npy");
  const int seeds = o.get_int("seeds", 1);
  if (seeds < 1) throw riner::InputError("--seeds must be at least 1");
  riner::Scan scan = riner::load_scan(scan_path);
  riner::Device device = riner::Device::open(o.device);
  riner::FbpOptions fbp_options;
  fbp_options.device = device;
  const riner::Array fbp_image = riner::fbp(scan, fbp_options);
  riner::RinerConfig config = riner::bench::config_from(o);
  const std::uint64_t first_seed = config.training.seed;
  std::vector<Result> rows;
  int ring_pass = 0, speck_pass = 0, centre_pass = 0, edge_pass = 0, kept_pass = 0;
  for (int i = 0; i < seeds; ++i) {
    config.training.seed = first_seed + static_cast<std::uint64_t>(i);
    nlohmann::json run =
        real_scan_run(scan, fbp_image, config, device, i == 0 ? o.get("png", "") : "",
                      i == 0 ? o.get("npy", "") : "");
    ring_pass += run["riner_ring_index"].get<double>() <= run["fbp_ring_index"].get<double>() / 3.0;
    speck_pass +=
        run["riner_specks_per_10k"].get<double>() <= run["fbp_specks_per_10k"].get<double>();
    centre_pass += run["centre_deviation_sigmas"].get<double>() <= 1.0;
    edge_pass += run["edge_ratio"].get<double>() >= riner::kSoftEdgeRatio;
    kept_pass += run["lost_object_pixels"].get<std::size_t>() == 0;
    run["scan"] = scan_path;
    rows.push_back({"riner_real_scan", std::move(run)});
  }
  if (seeds > 1) {
    rows.push_back({"riner_real_scan_bars",
                    {{"scan", scan_path},
                     {"seeds", seeds},
                     {"first_seed", first_seed},
                     {"ring_index_at_most_fbp_third", ring_pass},
                     {"specks_at_most_fbp", speck_pass},
                     {"centre_within_1_sigma", centre_pass},
                     {"edges_at_least_0_8_of_fbp", edge_pass},
                     {"no_lost_object", kept_pass}}});
  }
  return rows;
}

}  // namespace

RINER_BENCH_CASE(riner_real_scan, "FBP and Riner on a real scan (ring index, PNG pair)",
                 riner_real_scan);
