// riner destripe: classical stripe removal on the sinogram (riner/destripe.hpp), optionally
// followed by FBP for a ring-free first image in seconds.
#include <chrono>
#include <cstdio>

#include "cli_common.hpp"
#include "commands.hpp"
#include "riner/destripe.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "scan_options.hpp"
#include "summary_json.hpp"

namespace riner::app {

namespace {

std::size_t window_option(const Args& args, const char* name) {
  if (args.get(name).empty()) return 0;
  const long n = args.integer(name);
  if (n < 1) throw UsageError(std::string("--") + name + " must be 1 or more");
  return static_cast<std::size_t>(n);
}

double positive_option(const Args& args, const char* name) {
  const double x = args.number(name);
  if (!(x > 0.0)) throw UsageError(std::string("--") + name + " must be positive");
  return x;
}

// An integer option in [least, most]; `unset` when not given.
int bounded_option(const Args& args, const char* name, int least, int most, int unset) {
  if (args.get(name).empty()) return unset;
  const long n = args.integer(name);
  if (n < least || n > most) {
    throw UsageError(std::string("--") + name + " must be " + std::to_string(least) + ".." +
                     std::to_string(most));
  }
  return static_cast<int>(n);
}

}  // namespace

DestripeOptions destripe_options_from(const Args& args, const std::string& method) {
  DestripeOptions options;
  options.method = parse_destripe_method(method);
  options.size = window_option(args, "size");
  options.large_size = window_option(args, "large-size");
  options.rank_window = window_option(args, "rank-window");
  options.snr = positive_option(args, "snr");
  options.sigma = args.get("sigma").empty() ? 0.0 : positive_option(args, "sigma");
  options.fit_order = bounded_option(args, "fit-order", 0, 10, options.fit_order);
  options.levels = bounded_option(args, "levels", 0, 10, 0);  // 0: as many as fit, as unset
  options.wavelet_order = bounded_option(args, "wavelet", 1, 12, options.wavelet_order);
  options.engine = engine_from(args);
  options.device = device_from(args, options.engine);
  return options;
}

void add_destripe_tuning(Args& args) {
  args.option("size", "N",
              "median window across columns for small stripes (odd; default 21, in all 5: "
              "wider for wide stripes, narrower where the object's detail is finer)",
              "")
      .option("large-size", "N", "the window for large and dead stripes (default 51)", "")
      .option("rank-window", "N",
              "the sorting step's mean of its correction over N neighbouring ranks of each "
              "sorted column (odd; default: a sixth of the views; 1: Vo's as published)",
              "")
      .option("snr", "X", "how far above the noise a stripe must stand to be detected", "3")
      .option("sigma", "S",
              "the Gaussian's width in frequency bins (default: the method's own): filtering's "
              "low-pass along the views (3), fitting's across columns (10, smaller is "
              "stronger), wavelet's high-pass along the views (1, larger is stronger)",
              "")
      .option("fit-order", "N", "fitting: the polynomial's order along the views", "2")
      .option("levels", "N",
              "wavelet: decomposition levels (default or 0: as many as fit, up to 4)", "")
      .option("wavelet", "N", "wavelet: Daubechies' order (db N)", "9");
}

int run_destripe(int argc, char** argv, int first) {
  Args args("destripe",
            "Classical stripe (ring) removal on the sinogram: Vo et al.'s sorting, filtering, "
            "fitting, large-stripe and dead-stripe methods and their combination (all, the "
            "paper's \"Super\"), Münch et al.'s wavelet-Fourier filter (wavelet, the paper's "
            "\"WaveFFT\"), or a normalisation of each element's mean. Writes the destriped scan "
            "(sino.npy with its geometry.json: a scan riner reads again), stripes.npy (each "
            "element's mean over the views of what was removed, rho) and response.npy "
            "(exp(-stripes): the detector response the filter read, as alpha.npy) into the "
            "output folder; with --reconstruct, also its FBP (image.nii, image.png).");
  add_scan_options(args);
  args.option("out", "DIR", "output folder (created if missing)")
      .option("method", "NAME", "normalise, sorting, filtering, fitting, wavelet, large, dead or all", "all");
  add_destripe_tuning(args);
  args.flag("reconstruct",
            "also FBP the destriped scan (image.nii, image.png), with the quality report "
            "against the FBP of the scan as it came (rings, specks, edges, lost object)")
      .option("filter", "NAME", "FBP filter with --reconstruct: ram-lak, shepp-logan or hann",
              "ram-lak");
  add_engine_flags(args);
  args.output_flags();
  if (!args.parse(argc, argv, first)) return 0;
  Console console(args);
  const DestripeOptions options = destripe_options_from(args, args.get("method"));
  const FbpFilter filter = parse_fbp_filter(args.get("filter"));
  const LoadedScan loaded = scan_from(args, console);
  const Scan& scan = loaded.scan;
  // Before any work: --reconstruct filters the whole scan in one piece.
  if (args.is_set("reconstruct")) {
    check_piece_size(scan.geometry,
                     "--reconstruct (FBP of the whole scan; riner fbp SCAN --destripe METHOD goes "
                     "by slabs)");
  }
  const std::filesystem::path out = make_output_dir(args.get("out"));
  const std::vector<std::string> outputs = {"sino.npy",     "geometry.json", "stripes.npy",
                                            "response.npy", "image.nii",     "image.png",
                                            "summary.json"};
  refuse_outputs_over_inputs(out, outputs);
  const auto start = std::chrono::steady_clock::now();
  DestripeReport report;
  const Array destriped = destripe(scan.measurement, scan.geometry, options, &report);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  clear_previous_outputs(out, outputs);
  write_array(out / "sino.npy", destriped);
  write_text(out / "geometry.json", scan.geometry.to_json());
  write_array(out / "stripes.npy", report.removed);
  Array response = report.removed;
  for (float& x : response.data) x = std::exp(-x);
  write_array(out / "response.npy", response);
  char line[300];
  std::snprintf(line, sizeof(line),
                "destripe (%s, windows %zu and %zu, sigma %g): %zu dead and %zu large-stripe elements "
                "found, %zu non-finite or absurd readings interpolated, in %.2f s -> %s",
                destripe_method_name(options.method), report.size, report.large_size,
                report.sigma, report.dead.size(), report.large.size(), report.non_finite_replaced, seconds,
                out.string().c_str());
  console.line(line);
  note_large_stripes(console, report);
  nlohmann::json summary = {{"out", out.string()},
                            {"inputs", inputs_json(args)},
                            {"geometry_doubts", loaded.geometry_doubts},
                            {"method", destripe_method_name(options.method)},
                            {"size", report.size},
                            {"large_size", report.large_size},
                            {"rank_window", report.rank_window},
                            {"snr", options.snr},
                            {"sigma", report.sigma},
                            {"wavelet_levels", report.levels},
                            {"dead_elements", report.dead},
                            {"large_stripe_elements", report.large},
                            {"non_finite_replaced", report.non_finite_replaced},
                            {"seconds", seconds}};
  if (args.is_set("reconstruct")) {
    FbpOptions fbp_options;
    fbp_options.filter = filter;
    fbp_options.engine = options.engine;
    fbp_options.device = options.device;
    const auto fbp_start = std::chrono::steady_clock::now();
    const Array image = fbp(Scan{destriped, scan.geometry, 0}, fbp_options);
    const double fbp_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - fbp_start).count();
    write_array(out / "image.nii", image,
                {std::vector<double>(image.rank(), scan.geometry.voxel_mm)});
    write_png(out / "image.png", preview_image(image));
    summary["image"] = (out / "image.nii").string();
    summary["fbp_seconds"] = fbp_seconds;
    console.line("fbp of the destriped scan: " + shape_string(image.shape) + " in " +
                 std::to_string(fbp_seconds) + " s -> " + (out / "image.nii").string());
    // What the filter did to the image, against the FBP of the scan as it came: a median
    // across columns can take an object's detail for stripes (docs/guide/destripe.md).
    QualityCheck check;
    FbpOptions reference = fbp_options;
    reference.stopped_beam_at_floor = false;  // as reconstruct's quality reference
    check.image = quality_against_fbp(image, fbp(scan, reference), field_radius_px(scan.geometry));
    summary["quality"] = quality_summary(check);
    const QualityReport& q = check.image;
    std::snprintf(line, sizeof(line),
                  "against the scan's own FBP: ring index %.4f -> %.4f, specks %.2f -> %.2f per "
                  "10^4 pixels, edges at %.0f%% of FBP's",
                  q.fbp_ring_index, q.ring_index, q.fbp_specks_per_10k, q.specks_per_10k,
                  100.0 * q.edge_strength / q.fbp_edge_strength);
    console.line(line);
    print_quality_doubts(console, q);
  }
  write_text(out / "summary.json", summary.dump(1) + "\n");
  console.summary(summary);
  return 0;
}

}  // namespace riner::app
