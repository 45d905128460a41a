// A scanner-size projection stack through `riner reconstruct` by slabs (issue 30 item 7): a
// parallel-beam 3D Shepp-Logan (exact line integrals, the paper's responses and 10^7 photons)
// of --columns x --rows over --views views (180 degrees), the grid columns/2 square with 2 mm
// voxels (two detector rows per slice). The scan is written to disk and the CLI runs in its own
// process, so its peak memory is the slab run's alone: time, slices per minute, peak host
// memory against --memory-limit, PSNR per slice against the truth, and the same rows in one
// piece. A seam reads as a dip in the two slices either side of a slab border against the next
// two further in (seam_step_db, mean over the borders; negative: a seam); slices differ in
// content (the phantom's ends are mostly air), so each slice's PSNR is taken over the FBP's of
// the same slice first. --ranks=N runs the CLI under mpirun.
//
//   riner_bench --case=slab_stack [--columns=1024 --views=720 --rows=64] [--slab-slices=4]
//               [--memory-limit=SIZE] [--steps=N] [--one-piece=1] [--ranks=N] --out=DIR
//               [--png=FILE] [--riner=PATH] [--json=FILE]
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "harness.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/phantom.hpp"
#include "riner/simulate.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

riner::Geometry stack_geometry(std::size_t columns, std::size_t rows, std::size_t views) {
  riner::Geometry g;
  g.type = riner::GeometryType::kParallel3d;
  g.n_u = columns;
  g.n_v = rows;
  g.pitch_u = 1.0;
  g.pitch_v = 1.0;
  const riner::UniformAngles angles{views, 0.0, M_PI};
  g.uniform_angles = angles;
  g.angles = riner::uniform_angles(angles);
  g.volume_shape = {rows / 2, columns / 2, columns / 2};
  g.voxel_mm = 2.0;
  g.validate();
  return g;
}

struct RunOutcome {
  double wall = 0.0;
  nlohmann::json summary;
  std::vector<double> psnr;  // per slice
  riner::Array coronal;      // [slices, x] at the middle row
};

RunOutcome run_cli(const std::string& riner, const std::string& scan, const std::string& out,
                   const std::string& flags, const riner::Array& truth, double range) {
  const std::string command = riner + " reconstruct " + scan + " --out " + out + " " + flags +
                              " --quiet";
  std::printf("  %s\n", command.c_str());
  std::fflush(stdout);
  const auto t0 = std::chrono::steady_clock::now();
  const int status = std::system(command.c_str());
  RunOutcome r;
  r.wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
    throw riner::InputError("the run failed: " + command);
  std::ifstream in(out + "/summary.json");
  r.summary = nlohmann::json::parse(in);
  const std::size_t nz = truth.shape[0], ny = truth.shape[1], nx = truth.shape[2];
  r.coronal = riner::Array({nz, nx});
  for (std::size_t k = 0; k < nz; ++k) {
    char name[64];
    std::snprintf(name, sizeof(name), "/volume/slice_%05zu.tif", k);
    const riner::Array slice = riner::read_array(out + name).array;
    r.psnr.push_back(riner::psnr(slice, riner::axial_slice(truth, k), range));
    for (std::size_t x = 0; x < nx; ++x) r.coronal(k, x) = slice(ny / 2, x);
  }
  return r;
}

// Over the finite values: a slice that is air in the truth and in riner's image (the phantom's
// ends, carved whole) has no PSNR.
double mean(const std::vector<double>& v) {
  double s = 0.0;
  std::size_t n = 0;
  for (double x : v) {
    if (std::isfinite(x)) s += x, ++n;
  }
  return n == 0 ? 0.0 : s / static_cast<double>(n);
}

std::size_t slices_with_object(const riner::Array& truth) {
  const std::size_t per_slice = truth.shape[1] * truth.shape[2];
  std::size_t n = 0;
  for (std::size_t k = 0; k < truth.shape[0]; ++k) {
    const auto first = truth.data.begin() + static_cast<std::ptrdiff_t>(k * per_slice);
    n += std::any_of(first, first + static_cast<std::ptrdiff_t>(per_slice),
                     [](float v) { return v != 0.0f; });
  }
  return n;
}

std::vector<Result> slab_stack(const Options& o) {
  const std::size_t columns = static_cast<std::size_t>(o.get_int("columns", 1024));
  const std::size_t rows = static_cast<std::size_t>(o.get_int("rows", 64));
  const std::size_t views = static_cast<std::size_t>(o.get_int("views", 720));
  const int slab_slices = o.get_int("slab-slices", 4);
  const std::string memory = o.get("memory-limit", "");
  const int steps = o.get_int("steps", -1);
  const bool one_piece = o.get_int("one-piece", 1) != 0;
  const std::string dir = o.output_dir("out", "slab_stack");
  const std::string png = o.get("png", "");
  std::string riner = o.get("riner", "");
  if (riner.empty()) {
    riner = (std::filesystem::path(o.self).parent_path() / ".." / "apps" / "riner").string();
  }
  if (columns % 2 || rows % 2) throw riner::InputError("--columns and --rows must be even");

  const riner::Geometry g = stack_geometry(columns, rows, views);
  const riner::Phantom phantom = riner::shepp_logan(g, 0.02);
  const auto t0 = std::chrono::steady_clock::now();
  const riner::Array truth = riner::rasterize(phantom, g, 2);
  riner::RingModel model;
  model.seed = 1;
  const riner::Array alpha = riner::draw_responses(g, model);
  double scan_bytes = 0.0;
  double fbp_psnr = 0.0;
  std::vector<double> fbp_per_slice;
  riner::Array fbp_coronal;
  double range = 0.0;
  {
    riner::Scan scan;
    scan.geometry = g;
    scan.measurement =
        riner::corrupt_measurement(riner::exact_projections(phantom, g), alpha, model);
    scan_bytes = 4.0 * static_cast<double>(scan.measurement.size());
    riner::write_array(dir + "/sino.npy", scan.measurement);
    g.save(dir + "/geometry.json");
    float lo = truth.data[0], hi = truth.data[0];
    for (float v : truth.data) lo = std::min(lo, v), hi = std::max(hi, v);
    range = static_cast<double>(hi - lo);
    const riner::Array fbp = riner::fbp(scan, riner::FbpOptions{});
    for (std::size_t k = 0; k < truth.shape[0]; ++k)
      fbp_per_slice.push_back(
          riner::psnr(riner::axial_slice(fbp, k), riner::axial_slice(truth, k), range));
    fbp_psnr = mean(fbp_per_slice);
    fbp_coronal = riner::coronal_plane(fbp, truth.shape[1] / 2);
  }
  const double simulate_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("  simulated %zu views x %zu rows x %zu columns (%.0f MB as float) in %.0f s\n",
              views, rows, columns, scan_bytes / 1e6, simulate_seconds);

  // --slab-slices=0 leaves the slab size to riner (--flags="--slices-2d", say).
  std::string flags = slab_slices > 0 ? "--slab-slices " + std::to_string(slab_slices) : "";
  if (!memory.empty()) flags = "--memory-limit " + memory;
  if (steps > 0) flags += " --steps " + std::to_string(steps);
  // Anything else for the slabbed run (--flags="--workers 8").
  if (const std::string extra = o.get("flags", ""); !extra.empty()) flags += " " + extra;
  const std::string scan = dir + "/sino.npy";
  const int ranks = o.get_int("ranks", 1);
  const std::string launcher =
      ranks > 1 ? "mpirun --allow-run-as-root --oversubscribe -n " + std::to_string(ranks) + " " +
                      riner
                : riner;
  const RunOutcome slabbed = run_cli(launcher, scan, dir + "/slabbed", flags, truth, range);

  // The slices either side of each border between two slabs against the next ones further in.
  std::vector<double> gain(truth.shape[0]);
  for (std::size_t k = 0; k < gain.size(); ++k) gain[k] = slabbed.psnr[k] - fbp_per_slice[k];
  std::vector<double> at_border, inside, steps_at_border;
  for (const nlohmann::json& slab : slabbed.summary["per_slab"]) {
    const std::size_t k = slab["first_slice"];
    if (k < 2 || k + 1 >= gain.size()) continue;
    const double pair = (gain[k - 1] + gain[k]) / 2.0, next = (gain[k - 2] + gain[k + 1]) / 2.0;
    at_border.push_back(pair);
    inside.push_back(next);
    steps_at_border.push_back(pair - next);
  }

  RunOutcome whole;
  if (one_piece) {
    std::string whole_flags = "--slab-slices " + std::to_string(truth.shape[0]);
    if (steps > 0) whole_flags += " --steps " + std::to_string(steps);
    whole = run_cli(riner, scan, dir + "/one_piece", whole_flags, truth, range);
  }
  if (!png.empty()) {
    // Coronal planes side by side: truth | FBP | slabs | one piece, +z up, each slice drawn
    // as tall as needed for the strip to be at least 256 pixels high, in the truth's window.
    const std::size_t nz = truth.shape[0], nx = truth.shape[2];
    const std::size_t tall = std::max<std::size_t>(1, (256 + nz - 1) / nz);
    const riner::Array truth_coronal = riner::coronal_plane(truth, truth.shape[1] / 2);
    std::vector<const riner::Array*> panels = {&truth_coronal, &fbp_coronal, &slabbed.coronal};
    if (one_piece) panels.push_back(&whole.coronal);
    riner::Array strip({nz * tall, panels.size() * (nx + 4)}, 0.0f);
    for (std::size_t p = 0; p < panels.size(); ++p)
      for (std::size_t row = 0; row < nz * tall; ++row)
        for (std::size_t x = 0; x < nx; ++x)
          strip(row, p * (nx + 4) + x) = (*panels[p])(nz - 1 - row / tall, x);
    riner::write_png(png, strip, riner::percentile_window(truth_coronal, 1.0, 99.5));
  }
  const nlohmann::json& s = slabbed.summary;
  const double peak = s.value("peak_host_bytes", 0.0);
  const double limit = s.value("memory_limit_bytes", 0.0);
  const double slices_per_minute = 60.0 * static_cast<double>(truth.shape[0]) / slabbed.wall;
  return {{"slab_stack",
           {{"columns", columns},
            {"rows", rows},
            {"views", views},
            {"volume", truth.shape},
            {"slices_with_object", slices_with_object(truth)},
            {"scan_float_bytes", scan_bytes},
            {"slabs", s["slabs"]},
            {"slices_per_slab", s["slices_per_slab"]},
            {"memory_limit_bytes", limit},
            {"peak_host_bytes", peak},
            {"wall_seconds", slabbed.wall},
            {"slices_per_minute", slices_per_minute},
            {"workers", s.value("workers", 1)},
            {"psnr_mean", mean(slabbed.psnr)},
            {"gain_over_fbp_border_slices", mean(at_border)},
            {"gain_over_fbp_next_slices", mean(inside)},
            {"seam_step_db", mean(steps_at_border)},
            {"fbp_psnr_per_slice", fbp_per_slice},
            {"ranks", ranks},
            {"psnr_per_slice", slabbed.psnr},
            {"one_piece_psnr_mean", one_piece ? mean(whole.psnr) : 0.0},
            {"one_piece_wall_seconds", whole.wall},
            {"one_piece_peak_host_bytes",
             one_piece ? whole.summary.value("peak_host_bytes", 0.0) : 0.0},
            {"fbp_psnr_mean", fbp_psnr},
            {"flags", flags}},
           riner::bench::format(
               "%zu x %zu x %zu (%.0f MB): %d slabs of %d slices in %.0f s (%.2f slices/min), "
               "peak %.0f MB (limit %.0f MB) | PSNR %.2f dB (over FBP: border slices %+.2f, "
               "the next ones in %+.2f: seam step %+.2f) | one piece %.2f dB in %.0f s | FBP "
               "%.2f dB",
               views, rows, columns, scan_bytes / 1e6, s["slabs"].get<int>(),
               s["slices_per_slab"].get<int>(), slabbed.wall, slices_per_minute, peak / 1e6,
               limit / 1e6, mean(slabbed.psnr), mean(at_border), mean(inside),
               mean(steps_at_border), one_piece ? mean(whole.psnr) : 0.0, whole.wall, fbp_psnr)}};
}

}  // namespace

RINER_BENCH_CASE(slab_stack,
                 "a scanner-size parallel-beam stack by slabs: time, memory, seams, one piece",
                 slab_stack);
