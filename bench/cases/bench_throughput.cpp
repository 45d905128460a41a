// Issue 30's throughput mode: DeepLesion slices (the paper protocol) trained several at once
// on one device (riner/concurrent_trainings.hpp), against one at a time, on the same device in
// the same run. Reports slices per minute of the concurrent part and each slice's PSNR/SSIM,
// so a speed-up is read beside the accuracy it keeps.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <mutex>

#include "harness.hpp"
#include "riner/concurrent_trainings.hpp"
#include "riner/metrics.hpp"
#include "riner/reconstructor.hpp"
#include "scenes.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

std::vector<Result> throughput(const Options& o) {
  const int first = o.get_int("first", 0);
  const int last = o.get_int("last", o.size == "tiny" ? first + 1 : 7);
  const riner::RinerConfig config = riner::bench::config_from(o);
  const riner::Device device = riner::Device::open(o.device);
  const riner::Concurrency chosen = riner::concurrent_trainings(device.info());
  const std::vector<int> worker_counts =
      riner::bench::int_list(o.get("workers", "1," + std::to_string(chosen.trainings)));
  const riner::Projector projector(riner::preset_geometry("fan2d-paper"), riner::Engine::kOpenCL,
                                   device);
  // --copies=N trains the slices N times over: enough trainings to fill a big device.
  const int copies = std::max(1, o.get_int("copies", 1));
  std::vector<riner::bench::RingScene> scenes;
  for (int slice = first; slice <= last; ++slice) {
    scenes.push_back(riner::bench::paper_scene(o, slice, projector));
  }
  const std::size_t distinct = scenes.size();
  for (int c = 1; c < copies; ++c) {
    for (std::size_t i = 0; i < distinct; ++i) scenes.push_back(scenes[i]);
  }
  const char* threads = std::getenv("POCL_MAX_PTHREAD_COUNT");
  std::vector<Result> results;
  for (int workers : worker_counts) {
    std::vector<nlohmann::json> slices(scenes.size());
    std::mutex mutex;
    const auto started = std::chrono::steady_clock::now();
    riner::run_concurrently(
        scenes.size(), workers, device,
        [&](std::size_t i, int worker, const std::optional<riner::Device>& own) {
          riner::Reconstructor r(scenes[i].sim.scan, config, own);
          r.run();
          const riner::ImageMetrics m =
              riner::compare_images(r.result().image, scenes[i].sim.ground_truth);
          std::lock_guard<std::mutex> lock(mutex);
          slices[i] = {{"scene", scenes[i].name},  {"psnr", m.psnr},
                       {"ssim", m.ssim},           {"seconds", r.stats().seconds},
                       {"steps", r.stats().steps}, {"worker", worker}};
        });
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    double psnr = 0.0, ssim = 0.0, worst = 1e9;
    for (const nlohmann::json& s : slices) {
      psnr += s["psnr"].get<double>() / static_cast<double>(slices.size());
      ssim += s["ssim"].get<double>() / static_cast<double>(slices.size());
      worst = std::min(worst, s["psnr"].get<double>());
    }
    const double per_minute = 60.0 * static_cast<double>(slices.size()) / wall;
    std::fprintf(stderr,
                 "%d worker(s), %zu slices: %.1f s, %.2f slices/min (%.3f/s), PSNR %.2f (worst "
                 "%.2f) SSIM %.4f\n",
                 workers, slices.size(), wall, per_minute, per_minute / 60.0, psnr, worst, ssim);
    results.push_back(
        {"throughput",
         {{"workers", workers},
          {"workers_used", riner::usable_trainings(device.info(), workers)},
          {"chosen_workers", chosen.trainings},
          {"chosen_reason", chosen.reason},
          {"pocl_threads", threads ? threads : ""},
          {"slices", slices.size()},
          {"wall_seconds", wall},
          {"slices_per_minute", per_minute},
          {"psnr_mean", psnr},
          {"psnr_worst", worst},
          {"ssim_mean", ssim},
          {"per_slice", slices},
          {"config", nlohmann::json::parse(config.to_json())}},
         riner::bench::format("workers %d: %zu slices in %.1f s = %.2f/min, PSNR %.2f SSIM %.4f",
                              workers, slices.size(), wall, per_minute, psnr, ssim)});
  }
  return results;
}

}  // namespace

RINER_BENCH_CASE(throughput,
                 "DeepLesion slices trained several at once on one device (--workers=1,8) "
                 "against one at a time: slices per minute and PSNR",
                 throughput);
