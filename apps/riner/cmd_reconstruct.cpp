// riner reconstruct: Riner on a scan: the image, the detector's response and mask, the loss.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "cli_common.hpp"
#include "commands.hpp"
#include "detector_outputs.hpp"
#include "progress.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/quality.hpp"
#include "riner/reconstructor.hpp"
#include "riner/scan.hpp"
#include "scan_options.hpp"

namespace riner::app {

namespace {

nlohmann::json ring_summary(const std::optional<RingCorrection>& rings) {
  if (!rings) return {{"applied", false}};
  double largest = 0.0;
  for (double v : rings->profile) largest = std::max(largest, std::fabs(v));
  nlohmann::json out{{"applied", rings->applied},
                     {"measured_radii", rings->measured_radii},
                     {"mean_response_change", rings->mean_response_change},
                     {"radius_step_mm", rings->radius_step_mm},
                     {"largest_ring_per_mm", largest}};
  // The detector-response correction's evidence (null: no odd structure at all).
  if (rings->even_to_odd != 0.0) {
    out["even_to_odd"] = std::isfinite(rings->even_to_odd) ? nlohmann::json(rings->even_to_odd)
                                                           : nlohmann::json(nullptr);
  }
  return out;
}

// What a user without a ground truth can check (riner/quality.hpp): rings, specks and the
// centre against the FBP of the same scan, for the image and (the centre, 2D) the trained field.
struct QualityCheck {
  QualityReport image;
  std::optional<CentreDeviation> field;  // 2D only
};

QualityCheck check_quality(const Reconstructor& r, const ReconstructionResult& result,
                           const std::optional<Device>& device) {
  FbpOptions options;
  options.engine = r.config().engine;
  options.device = device;
  const Array fbp_image = fbp(r.scan(), options);
  QualityCheck check{quality_against_fbp(result.image, fbp_image), {}};
  if (fbp_image.rank() == 2) check.field = centre_deviation(result.field_image, fbp_image);
  return check;
}

nlohmann::json quality_summary(const QualityCheck& check) {
  const QualityReport& q = check.image;
  nlohmann::json out = {{"fbp_noise_per_mm", q.noise},
                        {"ring_index", q.ring_index},
                        {"fbp_ring_index", q.fbp_ring_index},
                        {"specks_per_10k_pixels", q.specks_per_10k},
                        {"fbp_specks_per_10k_pixels", q.fbp_specks_per_10k},
                        {"centre", nullptr}};
  if (check.field) {
    out["centre"] = {{"radius_px", q.centre.radius_px},
                     {"largest_broad_deviation_from_fbp_per_mm", q.centre.deviation},
                     {"at_px", q.centre.at_px},
                     {"fbp_profile_noise_per_mm", q.centre.fbp_noise},
                     {"fbp_noise_sigmas", q.centre.sigmas},
                     {"field_fbp_noise_sigmas", check.field->sigmas}};
  }
  return out;
}

// Where the tool has doubts, say so.
void print_doubts(Console& console, const QualityReport& q) {
  char line[200];
  if (q.centre.sigmas > 1.0) {
    std::snprintf(line, sizeof(line),
                  "note: near the rotation axis the image departs from FBP's broad profile by "
                  "%.1f times FBP's own noise there (a disc or dip rings can hide)",
                  q.centre.sigmas);
    console.line(line);
  }
  if (q.specks_per_10k > q.fbp_specks_per_10k) {
    std::snprintf(line, sizeof(line),
                  "note: %.1f isolated specks per 10^4 pixels against FBP's %.1f", q.specks_per_10k,
                  q.fbp_specks_per_10k);
    console.line(line);
  }
}

RinerConfig config_from(const Args& args) {
  // --paper is the base the file and the other flags adjust.
  RinerConfig config = args.is_set("paper") ? RinerConfig::paper() : RinerConfig();
  if (const std::string file = args.get("config"); !file.empty()) {
    config.update_from_json(read_text(file), file);
  }
  // Flags override the file.
  if (auto v = args.maybe("steps"); v && !v->empty())
    config.training.steps = static_cast<int>(args.integer("steps"));
  if (auto v = args.maybe("seed"); v && !v->empty())
    config.training.seed = static_cast<std::uint64_t>(args.integer("seed"));
  if (auto v = args.maybe("rays-per-step"); v && !v->empty()) {
    config.training.rays_per_step = static_cast<int>(args.integer("rays-per-step"));
  }
  if (auto v = args.maybe("lr"); v && !v->empty())
    config.training.learning_rate = args.number("lr");
  if (const std::string list = args.get("set"); !list.empty()) {
    for (const std::string& item : split_commas(list)) {
      const std::size_t eq = item.find('=');
      if (eq == std::string::npos || eq == 0) {
        throw UsageError("--set takes NAME=VALUE pairs separated by commas (got '" + item + "')");
      }
      config.set(item.substr(0, eq), item.substr(eq + 1));
    }
  }
  if (args.is_set("no-ring-correction")) {
    config.rings.air_reference = false;
    config.rings.gradient_reference = false;
    config.rings.response_reference = false;
  }
  config.engine = engine_from(args);
  config.validate();
  return config;
}

void write_history(const std::filesystem::path& path, const std::vector<LossRecord>& history) {
  std::string csv = "step,data_loss,penalty,learning_rate\n";
  char line[128];
  for (const LossRecord& r : history) {
    std::snprintf(line, sizeof(line), "%d,%.9g,%.9g,%.6g\n", r.step, r.data_loss, r.penalty,
                  r.learning_rate);
    csv += line;
  }
  write_text(path, csv);
}

}  // namespace

int run_reconstruct(int argc, char** argv, int first) {
  Args args("reconstruct",
            "Removes ring artifacts: trains Riner's neural field of the image together with each "
            "detector element's response alpha and validity beta, then writes the image "
            "(image.<format>, image.png), alpha.npy, beta.npy, detector.png, loss.csv, "
            "config.json and summary.json into the output folder.");
  add_scan_options(args);
  args.option("out", "DIR", "output folder (created if missing)")
      .option("format", "EXT", "image format: nii, npy, tif or raw", "nii")
      .option("config", "FILE", "settings JSON ({\"training\": {\"steps\": 4000}, ...})", "")
      .option("set", "NAME=VALUE,...",
              "change settings after --config (training.alpha_lr_scale=0.3; `riner settings` "
              "lists them)",
              "")
      .option("steps", "N",
              "training steps (default " + std::to_string(RinerConfig().training.steps) +
                  "; the learning rate halves every quarter of them)",
              "")
      .option("seed", "N", "random seed", "")
      .option("rays-per-step", "N",
              "rays per training step (default: the device's execution plan: 160 on a CPU, "
              "640 on a GPU)",
              "")
      .option("lr", "RATE", "initial learning rate", "")
      .option("report-every", "N", "steps between progress reports", "200")
      .flag("paper", "use the paper's settings (L=10, T=2^10, F=8, width 128, 4000 steps, ...)")
      .flag("no-ring-correction",
            "write the trained field and alpha as they are (no ring corrections)");
  add_engine_flags(args);
  args.output_flags();
  if (!args.parse(argc, argv, first)) return 0;
  Console console(args);
  LoadedScan loaded = scan_from(args, console);
  Scan& scan = loaded.scan;
  const RinerConfig config = config_from(args);
  const std::string format = args.get("format");
  if (format != "nii" && format != "npy" && format != "tif" && format != "raw") {
    throw UsageError("--format must be nii, npy, tif or raw");
  }
  const std::filesystem::path out = make_output_dir(args.get("out"));
  if (scan.non_finite > 0) {
    console.line(std::to_string(scan.non_finite) +
                 " measurements are NaN/inf (dead elements?): they count as 0 "
                 "and their elements' beta learns to switch them off");
  }

  const std::optional<Device> device = device_from(args, config.engine);
  Reconstructor reconstructor(std::move(scan), config, device);
  {
    const TrainingStats setup = reconstructor.stats();
    if (setup.plan) console.line(setup.plan->describe());
    if (setup.air_skipped) {
      char line[160];
      std::snprintf(line, sizeof(line),
                    "skipping the air: %.0f%% of the grid sampled, %.0f%% of the samples kept",
                    100.0 * setup.inside_fraction, 100.0 * setup.samples_kept_fraction);
      console.line(line);
    } else if (config.training.skip_air && !setup.air_note.empty()) {
      console.line("not skipping the air: " + setup.air_note);
    }
  }
  {
    Progress progress("reconstruct", static_cast<std::size_t>(config.training.steps),
                      console.quiet());
    reconstructor.run(
        [&](const TrainingProgress& p) {
          char status[64];
          std::snprintf(status, sizeof(status), "loss %.4g", p.loss);
          progress.update(static_cast<std::size_t>(p.step), status);
          return true;
        },
        static_cast<int>(args.integer("report-every")));
    progress.finish();
  }

  const Geometry& g = reconstructor.scan().geometry;
  const ReconstructionResult result = reconstructor.result();
  const Array& image = result.image;
  const Array& alpha = result.alpha;
  const std::filesystem::path image_path = out / ("image." + format);
  write_array(image_path, image, {std::vector<double>(image.rank(), g.voxel_mm)});
  write_png(out / "image.png", image);
  const std::vector<DeadElement> dead_report = reconstructor.dead_element_report();
  std::vector<std::size_t> dead;
  for (const DeadElement& d : dead_report) dead.push_back(d.element);
  write_detector_outputs(out, alpha, reconstructor.beta(), dead);
  write_history(out / "loss.csv", reconstructor.history());
  write_text(out / "config.json", reconstructor.config().to_json());  // as resolved for the device

  const TrainingStats stats = reconstructor.stats();
  const QualityCheck quality = check_quality(reconstructor, result, device);
  nlohmann::json summary = {
      {"image", image_path.string()},
      {"shape", image.shape},
      {"steps", stats.steps},
      {"steps_planned", stats.steps_planned},
      {"stopped_on_plateau", stats.stopped_on_plateau},
      {"seconds", stats.seconds},
      {"samples", stats.samples},
      {"samples_per_second", stats.seconds > 0 ? stats.samples / stats.seconds : 0.0},
      {"parameters", stats.parameters},
      {"non_finite_measurements", stats.non_finite},
      {"flat_field",
       loaded.flat_field ? flat_field_json(*loaded.flat_field) : nlohmann::json(nullptr)},
      {"centre", loaded.centre ? centre_json(*loaded.centre) : nlohmann::json(nullptr)},
      {"dead_elements", dead},
      {"dead_element_reasons", dead_elements_json(dead_report)},
      {"engine", stats.engine},
      {"device", stats.device},
      {"plan", stats.plan ? nlohmann::json::parse(stats.plan->to_json()) : nlohmann::json()},
      {"skip_air",
       {{"applied", stats.air_skipped},
        {"grid_fraction_sampled", stats.inside_fraction},
        {"samples_kept_fraction", stats.samples_kept_fraction},
        {"noise_sigma", stats.noise},
        {"note", config.training.skip_air ? stats.air_note : "off (training.skip_air)"}}},
      {"coverage",
       {{"rays", stats.coverage.rays},
        {"rays_per_element_fewest", stats.coverage.fewest},
        {"rays_per_element_median", stats.coverage.median},
        {"rays_per_element_most", stats.coverage.most},
        {"elements_under_10_rays", stats.coverage.elements_under_10}}},
      {"memory",
       {{"peak_host_mb", static_cast<double>(stats.peak_host_bytes) / 1048576.0},
        {"peak_device_buffers_mb", static_cast<double>(stats.peak_device_bytes) / 1048576.0}}},
      {"quality", quality_summary(quality)},
      {"air_ring_correction", ring_summary(result.air_rings)},
      {"gradient_ring_correction", ring_summary(result.gradient_rings)},
      {"response_ring_correction", ring_summary(result.response_rings)},
      {"final_loss",
       reconstructor.history().empty() ? 0.0 : reconstructor.history().back().data_loss}};
  write_text(out / "summary.json", summary.dump(1) + "\n");
  console.line("reconstructed " + shape_string(image.shape) + " in " +
               format_duration(stats.seconds) + " (" + std::to_string(stats.steps) + " steps, " +
               std::to_string(dead.size()) + " elements flagged dead) -> " + out.string());
  print_doubts(console, quality.image);
  console.summary(summary);
  return 0;
}

}  // namespace riner::app
