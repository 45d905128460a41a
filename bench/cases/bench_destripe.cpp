// Classical stripe removal side by side on the paper's protocol (DeepLesion slices, fan beam,
// the paper's responses and dead elements): FBP of the ringed scan, FBP after each method of
// riner/destripe.hpp, and the oracle FBP of the same scan with a perfect detector; PSNR/SSIM
// against the ground truth and the seconds of each filter.
//
//   riner_bench --case=destripe [--first=0] [--last=9] [--wavelet=9] [--levels=0]
//               [--window=21] [--large_window=51] [--stripe_free=1] [--json=FILE]
// (--wavelet and --levels: the wavelet method's Daubechies order and levels; --window and
// --large_window: the median windows, 0 for the literature's 21 and 51; --size is the
// harness's own; --stripe_free: the same scans with a perfect detector, where a filter can only
// take away.)
//
// And on a real scan, where there is no ground truth: each method's FBP against the scan's own
// FBP through the quality report (ring index, specks, edge strength, lost object), with a PNG
// grid of the ten images at FBP's window.
//
//   riner_bench --case=destripe_real_scan [--scan=../shared/data/neutron360/sino.npy]
//               [--png=PREFIX] [--json=FILE]
#include <chrono>
#include <cstdio>

#include "harness.hpp"
#include "riner/destripe.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/quality.hpp"
#include "riner/scan.hpp"
#include "scenes.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

const std::vector<riner::DestripeMethod> kMethods = {
    riner::DestripeMethod::kNormalise, riner::DestripeMethod::kSorting,
    riner::DestripeMethod::kFiltering, riner::DestripeMethod::kFitting,
    riner::DestripeMethod::kWavelet,   riner::DestripeMethod::kLarge,
    riner::DestripeMethod::kDead,      riner::DestripeMethod::kAll};

riner::DestripeOptions method_options(const Options& o, riner::DestripeMethod method,
                                      const riner::Device& device) {
  riner::DestripeOptions options;
  options.method = method;
  options.wavelet_order = o.get_int("wavelet", options.wavelet_order);
  options.levels = o.get_int("levels", options.levels);
  options.size = static_cast<std::size_t>(o.get_int("window", 0));
  options.large_size = static_cast<std::size_t>(o.get_int("large_window", 0));
  options.device = device;
  return options;
}

std::vector<Result> destripe_case(const Options& o) {
  const int first = o.get_int("first", 0);
  const int last = o.get_int("last", o.size == "tiny" ? first : 9);
  riner::Device device = riner::Device::open(o.device);
  const riner::Projector projector(riner::preset_geometry("fan2d-paper"), riner::Engine::kOpenCL,
                                   device);
  riner::FbpOptions fbp_options;
  fbp_options.device = device;
  const std::vector<riner::DestripeMethod>& methods = kMethods;
  struct Total {
    double psnr = 0.0, ssim = 0.0, seconds = 0.0;
  };
  std::map<std::string, Total> totals;
  std::vector<std::string> order = {"fbp"};
  for (auto m : methods) order.push_back(riner::destripe_method_name(m));
  order.push_back("oracle fbp");
  std::vector<Result> results;
  int scenes = 0;
  for (int index = first; index <= last; ++index, ++scenes) {
    riner::RingModel model;
    if (o.get_int("stripe_free", 0) != 0) {
      model.nonideal_fraction = 0.0;
      model.dead_elements = 0;
    }
    const riner::bench::RingScene scene = riner::bench::paper_scene(o, index, projector, model);
    const riner::Scan& scan = scene.sim.scan;
    nlohmann::json row{{"scene", scene.name}};
    std::string line = scene.name;
    auto score = [&](const std::string& name, const riner::Array& measurement, double seconds) {
      const riner::Array image = riner::fbp(riner::Scan{measurement, scan.geometry, 0}, fbp_options);
      const riner::ImageMetrics m = riner::compare_images(image, scene.sim.ground_truth);
      row[name] = {{"psnr", m.psnr}, {"ssim", m.ssim}, {"seconds", seconds}};
      totals[name].psnr += m.psnr;
      totals[name].ssim += m.ssim;
      totals[name].seconds += seconds;
      line += riner::bench::format(" | %s %.2f/%.3f", name.c_str(), m.psnr, m.ssim);
    };
    score("fbp", scan.measurement, 0.0);
    for (riner::DestripeMethod method : methods) {
      const riner::DestripeOptions options = method_options(o, method, device);
      const auto start = std::chrono::steady_clock::now();
      const riner::Array clean = riner::destripe(scan.measurement, scan.geometry, options);
      const double seconds =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      score(riner::destripe_method_name(method), clean, seconds);
    }
    score("oracle fbp", scene.sim.clean, 0.0);
    std::fprintf(stderr, "%s\n", line.c_str());
    results.push_back({"destripe", row, line});
  }
  nlohmann::json mean{{"scene", "mean"}, {"scenes", scenes}};
  std::string line = "mean:";
  for (const std::string& name : order) {
    const Total& t = totals[name];
    mean[name] = {{"psnr", t.psnr / scenes}, {"ssim", t.ssim / scenes},
                  {"seconds", t.seconds / scenes}};
    line += riner::bench::format("\n  %-12s %6.2f dB  SSIM %.3f  %.3f s", name.c_str(),
                                 t.psnr / scenes, t.ssim / scenes, t.seconds / scenes);
  }
  results.push_back({"destripe", mean, line});
  return results;
}

// Images of one shape in a grid `across` wide (row-major), the rest of the last row empty.
riner::Array grid(const std::vector<riner::Array>& images, std::size_t across) {
  const std::size_t ny = images.front().shape[0], nx = images.front().shape[1];
  const std::size_t down = (images.size() + across - 1) / across;
  riner::Array out({down * ny, across * nx});
  for (std::size_t k = 0; k < images.size(); ++k) {
    const std::size_t r0 = (k / across) * ny, c0 = (k % across) * nx;
    for (std::size_t i = 0; i < ny; ++i) {
      for (std::size_t j = 0; j < nx; ++j) out(r0 + i, c0 + j) = images[k](i, j);
    }
  }
  return out;
}

std::vector<Result> destripe_real_scan(const Options& o) {
  const std::string path = o.get("scan", "../shared/data/neutron360/sino.npy");
  const riner::Scan scan = riner::load_scan(path);
  if (scan.geometry.is_3d()) throw riner::InputError("destripe_real_scan takes a 2D scan");
  riner::Device device = riner::Device::open(o.device);
  riner::FbpOptions fbp_options;
  fbp_options.device = device;
  const riner::Array fbp_image = riner::fbp(scan, fbp_options);
  const double field = riner::field_radius_px(scan.geometry);
  std::vector<riner::Array> images{fbp_image};
  std::vector<Result> results;
  for (riner::DestripeMethod method : kMethods) {
    const riner::DestripeOptions options = method_options(o, method, device);
    const auto start = std::chrono::steady_clock::now();
    riner::DestripeReport report;
    const riner::Array clean = riner::destripe(scan.measurement, scan.geometry, options, &report);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    images.push_back(riner::fbp(riner::Scan{clean, scan.geometry, 0}, fbp_options));
    const riner::QualityReport q = riner::quality_against_fbp(images.back(), fbp_image, field);
    const std::string name = riner::destripe_method_name(method);
    nlohmann::json row{{"scan", path},
                       {"method", name},
                       {"fbp_ring_index", q.fbp_ring_index},
                       {"ring_index", q.ring_index},
                       {"fbp_specks_per_10k", q.fbp_specks_per_10k},
                       {"specks_per_10k", q.specks_per_10k},
                       {"edge_ratio", q.edge_strength / q.fbp_edge_strength},
                       {"lost_object_pixels", q.lost.pixels},
                       {"lost_object_share", q.lost.share},
                       {"centre_deviation_sigmas", q.centre.sigmas},
                       {"dead", report.dead.size()},
                       {"large", report.large.size()},
                       {"seconds", seconds}};
    std::string line = riner::bench::format("%-10s rings %.4f (FBP %.4f)  specks %.2f (FBP %.2f)  edges %.2f  lost %zu px  centre %.2f sigma  %.3f s",
                                 name.c_str(), q.ring_index, q.fbp_ring_index, q.specks_per_10k,
                                 q.fbp_specks_per_10k, q.edge_strength / q.fbp_edge_strength,
                                 q.lost.pixels, q.centre.sigmas, seconds);
    results.push_back({"destripe_real_scan", std::move(row), line});
  }
  const std::string png = o.get("png", "");
  if (!png.empty()) {
    // FBP, then the methods in kMethods' order, at FBP's window.
    riner::write_png(png + "_destripe.png", grid(images, 3),
                     riner::percentile_window(fbp_image, 1.0, 99.5));
  }
  return results;
}

}  // namespace

RINER_BENCH_CASE(destripe_real_scan,
                 "classical stripe removal + FBP on a real scan: the quality report per method",
                 destripe_real_scan);

RINER_BENCH_CASE(destripe, "classical stripe removal + FBP side by side (DeepLesion slices)",
                 destripe_case);
