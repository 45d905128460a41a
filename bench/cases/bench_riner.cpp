// Riner end to end: the paper protocol on the DeepLesion slices (accuracy and run time, with
// FBP beside it), a parallel-beam Shepp-Logan ring scan, and the real neutron scan.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "harness.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/phantom.hpp"
#include "riner/reconstructor.hpp"
#include "riner/scan.hpp"
#include "riner/simulate.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

std::string option(const Options& o, const std::string& key, const std::string& fallback) {
  auto it = o.extra.find(key);
  return it == o.extra.end() ? fallback : it->second;
}

// --config=FILE or inline JSON, then --steps.
riner::RinerConfig config_from(const Options& o) {
  riner::RinerConfig config;
  const std::string c = option(o, "config", "");
  if (!c.empty()) {
    if (std::filesystem::exists(c)) {
      std::ifstream f(c);
      config.update_from_json(
          std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()), c);
    } else {
      config.update_from_json(c, "--config");
    }
  }
  if (o.size == "tiny") config.training.steps = 300;
  const std::string steps = option(o, "steps", "");
  if (!steps.empty()) config.training.steps = std::stoi(steps);
  config.engine = riner::parse_engine(option(o, "engine", "opencl"));
  return config;
}

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
  const std::string dir = option(o, "data", "../shared/data/deeplesion");
  const int first = std::stoi(option(o, "first", "0"));
  const int last = std::stoi(option(o, "last", o.size == "tiny" ? "0" : "9"));
  const int every = std::stoi(option(o, "checkpoint", "1000"));
  const std::string png_dir = option(o, "png", "");
  const riner::RinerConfig config = config_from(o);
  riner::Device device = riner::Device::open(o.device);
  const riner::Geometry g = riner::preset_geometry("fan2d-paper");
  const riner::Projector projector(g, riner::Engine::kOpenCL, device);
  riner::FbpOptions fbp_options;
  fbp_options.device = device;
  std::vector<Result> results;
  for (int slice = first; slice <= last; ++slice) {
    const std::filesystem::path path = dir + "/slice_" + std::to_string(slice) + ".nii";
    if (!std::filesystem::exists(path))
      throw std::runtime_error(path.string() + " not found (--data=DIR)");
    riner::Array truth = riner::read_array(path).array;
    for (float& v : truth.data) v *= 0.1f;  // 1/cm -> 1/mm (METHOD.md section 4)
    riner::RingModel model;
    model.seed = static_cast<std::uint64_t>(slice);
    const riner::SimulatedScan sim = riner::simulate(truth, projector, model);
    const riner::Array fbp_image = riner::fbp(sim.scan, fbp_options);
    const riner::ImageMetrics fbp = riner::compare_images(fbp_image, truth);

    riner::Reconstructor r(sim.scan, config,
                           config.engine == riner::Engine::kOpenCL
                               ? std::optional<riner::Device>(device)
                               : std::nullopt);
    std::vector<nlohmann::json> curve;
    train_and_measure(r, truth, every, &curve);
    const riner::Array image = r.image();
    const riner::ImageMetrics m = riner::compare_images(image, truth);
    const riner::Array alpha = r.alpha();
    const riner::Array beta = r.beta();
    double alpha_error = 0.0;
    int live = 0;
    int live_off = 0;
    nlohmann::json dead = nlohmann::json::array();
    for (std::size_t e = 0; e < alpha.size(); ++e) {
      if (sim.alpha.data[e] > 0.0f) {
        alpha_error += std::fabs(alpha.data[e] - sim.alpha.data[e]);
        ++live;
        live_off += beta.data[e] < 0.5f;
        continue;
      }
      // A dead element whose rays barely cross the object cannot be told from a live one.
      double clean_mean = 0.0;
      for (std::size_t v = 0; v < g.n_views(); ++v) clean_mean += sim.clean(v, e);
      clean_mean /= static_cast<double>(g.n_views());
      dead.push_back({{"element", e},
                      {"beta", beta.data[e]},
                      {"flagged", beta.data[e] < 0.5f},
                      {"clean_mean", clean_mean}});
    }
    const riner::TrainingStats st = r.stats();
    if (!png_dir.empty()) {
      const std::size_t n = 256;
      riner::Array panel({n, 3 * n});
      for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t k = 0; k < n; ++k) {
          panel(i, k) = truth(i, k);
          panel(i, n + k) = fbp_image(i, k);
          panel(i, 2 * n + k) = image(i, k);
        }
      }
      riner::write_png(png_dir + "/deeplesion_slice" + std::to_string(slice) + ".png", panel,
                       riner::Window{0.0f, 0.035f});
    }
    results.push_back({"riner_deeplesion",
                       {{"slice", slice},
                        {"psnr", m.psnr},
                        {"ssim", m.ssim},
                        {"fbp_psnr", fbp.psnr},
                        {"fbp_ssim", fbp.ssim},
                        {"alpha_mae_live", alpha_error / live},
                        {"live_switched_off", live_off},
                        {"dead", dead},
                        {"seconds", st.seconds},
                        {"steps", st.steps},
                        {"samples_per_second", st.samples / st.seconds},
                        {"engine", st.engine},
                        {"curve", curve},
                        {"config", nlohmann::json::parse(config.to_json())}}});
    std::fprintf(stderr, "slice %d: PSNR %.2f SSIM %.4f (FBP %.2f) in %.1fs\n", slice, m.psnr,
                 m.ssim, fbp.psnr, st.seconds);
  }
  return results;
}

// A parallel-beam Shepp-Logan ring scan (180 degrees, off-centre axis).
std::vector<Result> riner_parallel_shepp_logan(const Options& o) {
  riner::Geometry g;
  g.type = riner::GeometryType::kParallel2d;
  g.n_u = 367;
  g.pitch_u = 1.0;
  g.offset_u = 3.5;
  g.voxel_mm = 1.0;
  g.volume_shape = {256, 256};
  g.uniform_angles = riner::UniformAngles{360, 0.0, M_PI};
  g.angles = riner::uniform_angles(*g.uniform_angles);
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
  const riner::RinerConfig config = config_from(o);
  riner::Reconstructor r(scan, config, fbp_options.device);
  std::vector<nlohmann::json> curve;
  train_and_measure(r, truth, std::stoi(option(o, "checkpoint", "2000")), &curve);
  const riner::ImageMetrics m = riner::compare_images(r.image(), truth);
  return {{"riner_parallel_shepp_logan",
           {{"psnr", m.psnr},
            {"ssim", m.ssim},
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

// A real scan (neutron360 by default): FBP and Riner side by side, ring index of each.
std::vector<Result> riner_real_scan(const Options& o) {
  const std::string scan_path = option(o, "scan", "../shared/data/neutron360/sino.npy");
  const std::string png = option(o, "png", "");
  riner::Scan scan = riner::load_scan(scan_path);
  riner::Device device = riner::Device::open(o.device);
  riner::FbpOptions fbp_options;
  fbp_options.device = device;
  const riner::Array fbp_image = riner::fbp(scan, fbp_options);
  const riner::RinerConfig config = config_from(o);
  riner::Reconstructor r(scan, config, device);
  r.run();
  const riner::Array image = r.image();
  const riner::Array beta = r.beta();
  int off = 0;
  for (float b : beta.data) off += b < 0.5f;
  if (!png.empty()) {
    // FBP | Riner at the same window (FBP's percentiles), then the central quarter enlarged.
    const std::size_t ny = image.shape[0], nx = image.shape[1];
    riner::Array panel({ny, 2 * nx});
    for (std::size_t i = 0; i < ny; ++i) {
      for (std::size_t k = 0; k < nx; ++k) {
        panel(i, k) = fbp_image(i, k);
        panel(i, nx + k) = image(i, k);
      }
    }
    const riner::Window w = riner::percentile_window(fbp_image, 1.0, 99.5);
    riner::write_png(png + "_fbp_riner.png", panel, w);
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
  return {{"riner_real_scan",
           {{"scan", scan_path},
            {"fbp_ring_index", riner::ring_index(fbp_image)},
            {"riner_ring_index", riner::ring_index(image)},
            {"elements_switched_off", off},
            {"seconds", r.stats().seconds},
            {"steps", r.stats().steps}}}};
}

}  // namespace

RINER_BENCH_CASE(riner_real_scan, "FBP and Riner on a real scan (ring index, PNG pair)",
                 riner_real_scan);
