// riner fbp: filtered backprojection (FBP, or FDK for cone beam) of a scan.
#include <chrono>

#include "cli_common.hpp"
#include "commands.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/scan.hpp"
#include "scan_options.hpp"
#include "summary_json.hpp"

namespace riner::app {

int run_fbp(int argc, char** argv, int first) {
  Args args("fbp",
            "Filtered backprojection of a scan: FBP for parallel and fan beam, FDK for cone "
            "beam. NaN/inf measurements (dead elements) are interpolated from their neighbours "
            "first. The image is written in the format of --out's extension.");
  add_scan_options(args);
  args.option("out", "IMAGE", "output image/volume (.nii, .npy, .tif, .raw)")
      .option("filter", "NAME", "ram-lak, shepp-logan or hann", "ram-lak")
      .flag("png", "also write a PNG preview beside the output");
  add_engine_flags(args);
  args.output_flags();
  if (!args.parse(argc, argv, first)) return 0;
  Console console(args);
  const LoadedScan loaded = scan_from(args, console);
  check_centre(loaded, console);
  const Scan& scan = loaded.scan;
  const std::filesystem::path out = args.get("out");
  format_from_path(out);  // reject an unknown extension before the work
  FbpOptions options;
  options.filter = parse_fbp_filter(args.get("filter"));
  options.engine = engine_from(args);
  options.device = device_from(args, options.engine);
  FbpReport report;
  const auto start = std::chrono::steady_clock::now();
  const Array image = fbp(scan, options, &report);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  write_array(out, image, {std::vector<double>(image.rank(), scan.geometry.voxel_mm)});
  if (args.is_set("png")) {
    std::filesystem::path png = out;
    png.replace_extension(".png");
    write_png(png, image);
  }
  if (report.short_scan) {
    console.line(
        "warning: the views do not cover the full circle; without Parker weights the "
        "image will show streaks");
  }
  console.line("fbp (" + std::string(fbp_filter_name(options.filter)) + ", " +
               engine_name(options.engine) + "): " + shape_string(image.shape) + " in " +
               std::to_string(seconds) + " s, " + std::to_string(report.non_finite_replaced) +
               " non-finite measurements interpolated -> " + out.string());
  console.summary(
      {{"out", out.string()},
       {"shape", image.shape},
       {"filter", fbp_filter_name(options.filter)},
       {"engine", engine_name(options.engine)},
       {"seconds", seconds},
       {"non_finite_replaced", report.non_finite_replaced},
       {"short_scan", report.short_scan},
       {"flat_field",
        loaded.flat_field ? flat_field_json(*loaded.flat_field) : nlohmann::json(nullptr)},
       {"centre", loaded.centre ? centre_json(*loaded.centre) : nlohmann::json(nullptr)}});
  return 0;
}

}  // namespace riner::app
