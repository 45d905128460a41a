// Accuracy of the simulation chain: projector vs exact line integrals, FBP on the DeepLesion
// protocol, FDK on a 3D Shepp-Logan (with a PNG of the central slices).
#include <cmath>
#include <filesystem>

#include "harness.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/phantom.hpp"
#include "riner/projector.hpp"
#include "riner/simulate.hpp"
#include "scenes.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

double relative_rms(const riner::Array& got, const riner::Array& want) {
  double d = 0, n = 0;
  for (std::size_t i = 0; i < got.size(); ++i) {
    const double e = static_cast<double>(got.data[i]) - want.data[i];
    d += e * e;
    n += static_cast<double>(want.data[i]) * want.data[i];
  }
  return std::sqrt(d / n);
}

riner::Geometry refined(riner::Geometry g, std::size_t factor) {
  for (auto& n : g.volume_shape) n *= factor;
  g.voxel_mm /= static_cast<double>(factor);
  return g;
}

// Joseph projections of Shepp-Logan rasters on ever finer grids vs the exact line integrals.
std::vector<Result> projector_accuracy(const Options& options) {
  riner::Device device = riner::Device::open(options.device);
  std::vector<Result> results;
  const riner::Geometry fan = riner::preset_geometry("fan2d-paper");
  for (std::size_t factor : {1, 2, 4}) {
    const riner::Geometry grid = refined(fan, factor);
    const riner::Phantom p = riner::shepp_logan(grid);
    const riner::Array raster = riner::rasterize(p, grid, 2);
    riner::Array projected;
    const double ms = riner::bench::time_ms([&] {
      projected = riner::Projector(grid, riner::Engine::kOpenCL, device).project(raster);
    });
    results.push_back(
        {"projector_accuracy",
         {{"geometry", "fan2d-paper"},
          {"grid", grid.volume_shape},
          {"voxel_mm", grid.voxel_mm},
          {"raster_supersample", 2},
          {"relative_rms", relative_rms(projected, riner::exact_projections(p, grid))},
          {"project_ms", ms}}});
  }
  // Cone beam over the cone3d-paper field of view on cube grids; 36 views keep it quick.
  riner::Geometry cone = riner::preset_geometry("cone3d-paper");
  cone.n_u = cone.n_v = 256;
  cone.pitch_u = cone.pitch_v = 2.4;
  cone.uniform_angles = riner::UniformAngles{36, 0.0, 2 * M_PI};
  cone.angles = riner::uniform_angles(*cone.uniform_angles);
  const std::size_t largest = options.size == "large" ? 640 : (options.size == "small" ? 256 : 512);
  for (std::size_t n : {128ul, 256ul, 512ul, 640ul}) {
    if (n > largest) break;
    riner::Geometry grid = cone;
    grid.volume_shape = {n, n, n};
    grid.voxel_mm = 256.0 / static_cast<double>(n);
    const riner::Phantom p = riner::shepp_logan(grid);
    const riner::Array raster = riner::rasterize(p, grid, n <= 256 ? 2 : 1);
    riner::Array projected;
    const double ms = riner::bench::time_ms([&] {
      projected = riner::Projector(grid, riner::Engine::kOpenCL, device).project(raster);
    });
    results.push_back(
        {"projector_accuracy",
         {{"geometry", "cone3d-paper field of view, 36 views, 256^2 detector"},
          {"grid", grid.volume_shape},
          {"voxel_mm", grid.voxel_mm},
          {"raster_supersample", n <= 256 ? 2 : 1},
          {"relative_rms", relative_rms(projected, riner::exact_projections(p, grid))},
          {"project_ms", ms}}});
  }
  return results;
}

// FBP on the paper protocol for each DeepLesion slice: clean and ring-corrupted.
std::vector<Result> fbp_deeplesion(const Options& options) {
  riner::Device device = riner::Device::open(options.device);
  const riner::Geometry g = riner::preset_geometry("fan2d-paper");
  const riner::Projector projector(g, riner::Engine::kOpenCL, device);
  riner::FbpOptions fbp_options;
  fbp_options.device = device;
  std::vector<Result> results;
  for (int slice = 0; slice < (options.size == "tiny" ? 1 : 10); ++slice) {
    const riner::bench::RingScene scene = riner::bench::paper_scene(options, slice, projector);
    const riner::SimulatedScan& sim = scene.sim;
    const riner::Array& truth = sim.ground_truth;
    riner::Array clean_image;
    const double ms = riner::bench::time_ms([&] {
      clean_image = riner::fbp(riner::Scan{sim.clean, g, 0}, fbp_options);
    });
    const riner::ImageMetrics clean = riner::compare_images(clean_image, truth);
    const riner::ImageMetrics rings =
        riner::compare_images(riner::fbp(sim.scan, fbp_options), truth);
    results.push_back({"fbp_deeplesion",
                       {{"scene", scene.name},
                        {"clean_psnr", clean.psnr},
                        {"clean_ssim", clean.ssim},
                        {"rings_psnr", rings.psnr},
                        {"rings_ssim", rings.ssim},
                        {"fbp_ms", ms}}});
  }
  return results;
}

// FDK of a 3D Shepp-Logan, 128^3 voxels of 2 mm, from exact cone-beam projections.
std::vector<Result> fdk_shepp_logan(const Options& options) {
  riner::Geometry g = riner::preset_geometry("cone3d-paper");
  g.volume_shape = {128, 128, 128};
  g.voxel_mm = 2.0;
  g.n_u = g.n_v = 200;
  g.pitch_u = g.pitch_v = 3.0;
  g.validate();
  const riner::Phantom p = riner::shepp_logan(g);
  const riner::Array truth = riner::rasterize(p, g, 2);
  const riner::Scan scan{riner::exact_projections(p, g), g, 0};
  riner::FbpOptions fbp_options;
  fbp_options.device = riner::Device::open(options.device);
  riner::Array volume;
  const double ms = riner::bench::time_ms([&] { volume = riner::fbp(scan, fbp_options); });
  riner::Array support(truth.shape, 0.0f);
  for (std::size_t i = 0; i < truth.size(); ++i)
    support.data[i] = truth.data[i] > 0.0f ? 1.0f : 0.0f;
  const riner::ImageMetrics inside = riner::compare_images(volume, truth, &support);
  // The central axial slice, where the cone angle is smallest.
  const std::size_t n = 128;
  riner::Array truth_slice({n, n});
  riner::Array fdk_slice({n, n});
  std::copy_n(truth.ptr() + (n / 2) * n * n, n * n, truth_slice.ptr());
  std::copy_n(volume.ptr() + (n / 2) * n * n, n * n, fdk_slice.ptr());
  const riner::ImageMetrics central = riner::compare_images(fdk_slice, truth_slice);
  // Central axial, coronal and sagittal slices: truth on top, FDK below.
  riner::Array panel({2 * n, 3 * n});
  for (int row = 0; row < 2; ++row) {
    const riner::Array& v = row == 0 ? truth : volume;
    for (std::size_t a = 0; a < n; ++a) {
      for (std::size_t b = 0; b < n; ++b) {
        panel(row * n + a, b) = v(n / 2, a, b);                  // axial: z = middle
        panel(row * n + a, n + b) = v(n - 1 - a, n / 2, b);      // coronal: y = middle, z up
        panel(row * n + a, 2 * n + b) = v(n - 1 - a, b, n / 2);  // sagittal: x = middle
      }
    }
  }
  const std::string out = options.output_dir("out", ".");
  riner::write_png(out + "/fdk_shepp_logan_128.png", panel, riner::Window{0.0f, 0.04f});
  return {{"fdk_shepp_logan",
           {{"grid", g.volume_shape},
            {"views", g.n_views()},
            {"detector", {g.n_v, g.n_u}},
            {"psnr_in_support", inside.psnr},
            {"ssim_in_support", inside.ssim},
            {"psnr_central_slice", central.psnr},
            {"ssim_central_slice", central.ssim},
            {"fdk_ms", ms},
            {"png", out + "/fdk_shepp_logan_128.png"}}}};
}

}  // namespace

RINER_BENCH_CASE(projector_accuracy, "Joseph projector vs exact Shepp-Logan integrals",
                 projector_accuracy);
RINER_BENCH_CASE(fbp_deeplesion, "FBP on the paper protocol, ten DeepLesion slices",
                 fbp_deeplesion);
RINER_BENCH_CASE(fdk_shepp_logan, "FDK of a 128^3 Shepp-Logan (PNG of central slices)",
                 fdk_shepp_logan);
