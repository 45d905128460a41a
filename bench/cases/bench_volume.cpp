// The paper's cone-beam protocol on a CT volume (issue 34): the volume is the ground truth on
// cone3d-paper's grid (256² x 100 voxels of 1 mm, 360 views, a 300 x 200 detector), projected by
// the Joseph projector (not riner's own ray sampler), with the paper's per-pixel responses, two
// dead pixels and Poisson noise. Beside riner: FDK of the ring scan and FDK of a perfect
// detector (the oracle). riner trains with checkpoints (PSNR/SSIM against training time); the
// process's peak memory is reported, and with --png a picture of the central axial, coronal and
// sagittal slices (truth | FDK | riner).
//
//   riner_bench --case=volume [--volume=FILE] [--spacing=Z,Y,X] [--seed=1] [--checkpoint=3000]
//               [--config=JSON] [--png=FILE] [--json=FILE]
//
// --volume: mu in 1/mm, [z, y, x] (default: the shared head volume); --spacing: its voxel size
// in mm, resampled onto the grid (default: the volume is taken as on the grid; its shape must
// then be the grid's).
#include <sys/resource.h>

#include <algorithm>
#include <cstdio>

#include "harness.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/projector.hpp"
#include "riner/reconstructor.hpp"
#include "riner/resample.hpp"
#include "riner/simulate.hpp"
#include "scenes.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

double peak_rss_mb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

// Central axial, coronal and sagittal slices of each volume, side by side in rows:
// truth | FDK | riner.
void write_panel(const std::string& path, const std::vector<const riner::Array*>& volumes) {
  const riner::Array& v0 = *volumes[0];
  const std::size_t nz = v0.shape[0], ny = v0.shape[1], nx = v0.shape[2];
  const std::size_t height = ny + 2 * nz, width = nx * volumes.size();
  riner::Array panel({height, width});
  for (std::size_t k = 0; k < volumes.size(); ++k) {
    const riner::Array& v = *volumes[k];
    for (std::size_t y = 0; y < ny; ++y) {
      for (std::size_t x = 0; x < nx; ++x) panel(y, k * nx + x) = v(nz / 2, y, x);
    }
    for (std::size_t z = 0; z < nz; ++z) {
      for (std::size_t x = 0; x < nx; ++x) {
        panel(ny + (nz - 1 - z), k * nx + x) = v(z, ny / 2, x);      // coronal, head up
      }
      for (std::size_t y = 0; y < std::min(ny, nx); ++y) {
        panel(ny + nz + (nz - 1 - z), k * nx + y) = v(z, y, nx / 2);  // sagittal
      }
    }
  }
  riner::write_png(path, panel, riner::percentile_window(*volumes[0], 1.0, 99.5));
}

std::vector<Result> volume_case(const Options& o) {
  const std::string path = o.get("volume", "../shared/data/head_volume/head_mu.npy");
  const std::string spacing = o.get("spacing", path.find("head_mu") != std::string::npos
                                                   ? "1.5,3.2,3.2"
                                                   : "");
  const int every = o.get_int("checkpoint", 3000);
  riner::RinerConfig config = riner::bench::config_from(o);
  riner::Device device = riner::Device::open(o.device);
  const riner::Geometry g = riner::preset_geometry("cone3d-paper");
  riner::Array truth = riner::read_array(path).array;
  if (!spacing.empty()) truth = riner::resample_to_grid(truth, riner::bench::number_list(spacing), g);
  riner::RingModel model;
  model.seed = static_cast<std::uint64_t>(o.get_int("seed", 1));
  const riner::Projector projector(g, riner::Engine::kOpenCL, device);
  const riner::SimulatedScan sim = riner::simulate(truth, projector, model);
  riner::FbpOptions fbp_options;
  fbp_options.device = device;
  const riner::Array fdk = riner::fbp(sim.scan, fbp_options);
  const riner::Array oracle = riner::fbp(riner::Scan{sim.clean, g, 0}, fbp_options);
  const riner::ImageMetrics fdk_m = riner::compare_images(fdk, sim.ground_truth);
  const riner::ImageMetrics oracle_m = riner::compare_images(oracle, sim.ground_truth);

  riner::Reconstructor r(sim.scan, config, device);
  std::vector<nlohmann::json> curve;
  const int total = r.config().training.steps;
  while (r.steps_done() < total) {
    r.step(std::min(every, total - r.steps_done()));
    const riner::ImageMetrics m = riner::compare_images(r.image(), sim.ground_truth);
    curve.push_back({{"step", r.steps_done()}, {"seconds", r.stats().seconds},
                     {"psnr", m.psnr}, {"ssim", m.ssim}});
    std::fprintf(stderr, "  step %d: %.2f dB / %.3f, %.0f s\n", r.steps_done(), m.psnr, m.ssim,
                 r.stats().seconds);
  }
  const riner::ReconstructionResult result = r.result();
  const riner::ImageMetrics m = riner::compare_images(result.image, sim.ground_truth);
  const riner::ImageMetrics field_m = riner::compare_images(result.field_image, sim.ground_truth);
  const riner::TrainingStats st = r.stats();
  const std::string png = o.get("png", "");
  if (!png.empty()) write_panel(png, {&sim.ground_truth, &fdk, &result.image});
  nlohmann::json fields =
      riner::bench::detector_accuracy(result.alpha, r.trained_beta(), sim, r.dead_elements());
  fields.update({{"volume", path},
                 {"spacing_mm", spacing.empty() ? "on the grid" : spacing},
                 {"psnr", m.psnr},
                 {"ssim", m.ssim},
                 {"edges", m.edge_ratio},
                 {"field_psnr", field_m.psnr},
                 {"residual_detail_applied", result.residual_detail.applied},
                 {"residual_detail_consistent_share", result.residual_detail.consistent_share},
                 {"residual_detail_seconds", result.residual_detail.seconds},
                 {"residual_detail_misfit",
                  {result.residual_detail.misfit_before, result.residual_detail.misfit_after}},
                 {"fdk_psnr", fdk_m.psnr},
                 {"fdk_ssim", fdk_m.ssim},
                 {"oracle_fdk_psnr", oracle_m.psnr},
                 {"oracle_fdk_ssim", oracle_m.ssim},
                 {"seconds", st.seconds},
                 {"steps", st.steps},
                 {"rays_per_step", r.config().training.rays_per_step},
                 {"log2_table_size", r.config().encoding.log2_table_size},
                 {"peak_rss_mb", peak_rss_mb()},
                 {"curve", curve}});
  const std::string line = riner::bench::format(
      "%s: riner %.2f dB / %.3f (edges %.2f; the field %.2f dB, residual detail %s at share "
      "%.3f) in %.0f s training, %d steps; FDK %.2f / %.3f, oracle FDK %.2f / %.3f; peak %.0f MB",
      path.c_str(), m.psnr, m.ssim, m.edge_ratio, field_m.psnr,
      result.residual_detail.applied ? "added" : "not added",
      result.residual_detail.consistent_share, st.seconds, st.steps, fdk_m.psnr, fdk_m.ssim,
      oracle_m.psnr, oracle_m.ssim, peak_rss_mb());
  return {{"volume", fields, line}};
}

}  // namespace

RINER_BENCH_CASE(volume, "the paper's cone-beam protocol on a CT volume (issue 34)", volume_case);
