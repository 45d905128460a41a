// riner compare: image quality against a reference (PSNR, SSIM, MAE, RMSE, edge ratio).
#include <cstdio>

#include "cli_common.hpp"
#include "commands.hpp"
#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"

namespace riner::app {

int run_compare(int argc, char** argv, int first) {
  Args args("compare",
            "Compares an image or volume with a reference: PSNR and SSIM as scikit-image "
            "computes them (data range = max - min of the reference), MAE, RMSE, and the "
            "edges' sharpness against the reference's (edge_ratio: 1 as sharp, below 1 "
            "blurred).");
  args.positional("IMAGE", "the image to judge")
      .positional("REFERENCE", "the ground truth, same shape")
      .option("mask", "KIND", "none, or circle (the inscribed disk/cylinder)", "none")
      .option("data-range", "R", "override the data range (default: the reference's)", "0");
  args.output_flags();
  if (!args.parse(argc, argv, first)) return 0;
  Console console(args);
  // 0 is the option's "not given"; anything else must be a range SSIM's constants can square.
  const double data_range = args.number("data-range");
  if (data_range != 0.0 && !(data_range > 0.0 && data_range <= 1e30)) {
    throw UsageError(
        "--data-range must be a positive number up to 1e30 (default: the "
        "reference's max - min)");
  }
  const Array image = read_array(args.get("IMAGE")).array;
  const Array reference = read_array(args.get("REFERENCE")).array;
  const std::string mask_kind = args.get("mask");
  if (mask_kind != "none" && mask_kind != "circle")
    throw UsageError("--mask must be none or circle");
  const Array mask = mask_kind == "circle" ? circle_mask(reference.shape) : Array();
  const ImageMetrics m =
      compare_images(image, reference, mask_kind == "circle" ? &mask : nullptr, data_range);
  char line[256];
  std::snprintf(line, sizeof(line),
                "PSNR %.4f dB  SSIM %.5f  MAE %.6g  RMSE %.6g  edges %.3f  (range %.6g, %zu "
                "pixels%s)",
                m.psnr, m.ssim, m.mae, m.rmse, m.edge_ratio, m.data_range, m.pixels,
                mask_kind == "circle" ? ", circle mask" : "");
  console.line(line);
  nlohmann::json summary = metrics_json(m.psnr, m.ssim, m.mae, m.rmse, m.data_range);
  summary["edge_ratio"] = m.edge_ratio;
  summary["pixels"] = m.pixels;
  summary["mask"] = mask_kind;
  console.summary(summary);
  return 0;
}

}  // namespace riner::app
