// Classical stripe removal side by side on the paper's protocol (DeepLesion slices, fan beam,
// the paper's responses and dead elements): FBP of the ringed scan, FBP after each method of
// riner/destripe.hpp, and the oracle FBP of the same scan with a perfect detector; PSNR/SSIM
// against the ground truth and the seconds of each filter.
//
//   riner_bench --case=destripe [--first=0] [--last=9] [--wavelet=9] [--levels=0]
//               [--json=FILE]
// (--wavelet and --levels: the wavelet method's Daubechies order and levels.)
#include <chrono>
#include <cstdio>

#include "harness.hpp"
#include "riner/destripe.hpp"
#include "riner/fbp.hpp"
#include "riner/metrics.hpp"
#include "scenes.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

std::vector<Result> destripe_case(const Options& o) {
  const int first = o.get_int("first", 0);
  const int last = o.get_int("last", o.size == "tiny" ? first : 9);
  riner::Device device = riner::Device::open(o.device);
  const riner::Projector projector(riner::preset_geometry("fan2d-paper"), riner::Engine::kOpenCL,
                                   device);
  riner::FbpOptions fbp_options;
  fbp_options.device = device;
  const std::vector<riner::DestripeMethod> methods = {
      riner::DestripeMethod::kNormalise, riner::DestripeMethod::kSorting,
      riner::DestripeMethod::kFiltering, riner::DestripeMethod::kFitting,
      riner::DestripeMethod::kWavelet, riner::DestripeMethod::kLarge,
      riner::DestripeMethod::kDead, riner::DestripeMethod::kAll};
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
    const riner::bench::RingScene scene = riner::bench::paper_scene(o, index, projector);
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
      riner::DestripeOptions options;
      options.method = method;
      options.wavelet_order = o.get_int("wavelet", options.wavelet_order);
      options.levels = o.get_int("levels", options.levels);
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

}  // namespace

RINER_BENCH_CASE(destripe, "classical stripe removal + FBP side by side (DeepLesion slices)",
                 destripe_case);
