// riner reconstruct: Riner on a scan: the image, the detector's response and mask, the loss.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <optional>

#include "cli_common.hpp"
#include "commands.hpp"
#include "detector_outputs.hpp"
#include "progress.hpp"
#include "reconstruct_slabs.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/folder_lock.hpp"
#include "riner/io.hpp"
#include "riner/quality.hpp"
#include "riner/reconstructor.hpp"
#include "riner/scan.hpp"
#include "riner/slab_ranks.hpp"
#include "scan_options.hpp"
#include "stop_signal.hpp"
#include "summary_json.hpp"

namespace riner::app {

namespace {

// Rays through only skipped air beside the object that read above air, beyond which the console
// says so: a few are a detector's spikes or scatter (neutron360: 4, a DeepLesion slice: 12 of
// 2e4-8e4); faint object cut away gives hundreds (a faint square's corners: 130 of 4e4).
constexpr std::size_t kNearRaysNoted = 10;
constexpr double kNearRaysShareNoted = 2e-3;

RinerConfig config_from(const Args& args) {
  // --paper is the base the file and the other flags adjust.
  RinerConfig config = args.is_set("paper") ? RinerConfig::paper() : RinerConfig();
  if (const std::string file = args.get("config"); !file.empty()) {
    config.update_from_json(read_text(file), file);
  }
  // Flags override the file.
  if (auto v = args.maybe("steps"); v && !v->empty())
    config.training.steps = static_cast<int>(args.integer("steps"));
  if (auto v = args.maybe("seed"); v && !v->empty()) {
    const long seed = args.integer("seed");
    if (seed < 0) throw UsageError("--seed must be 0 or more");  // -1 wrapped to 2^64 - 1
    config.training.seed = static_cast<std::uint64_t>(seed);
  }
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
    config.rings.mirror_reference = false;
    config.residual_detail.enabled = false;
  }
  config.engine = engine_from(args);
  config.validate();
  return config;
}

constexpr const char* kCheckpointName = "training.checkpoint";

// Without --resume, a checkpoint in the output folder is an unfinished run that a new one would
// overwrite: refused before anything is trained.
void refuse_unfinished(const Args& args, const std::filesystem::path& checkpoint) {
  if (!args.is_set("resume") && std::filesystem::exists(checkpoint)) {
    throw UsageError(checkpoint.string() +
                     " holds an unfinished training: --resume goes on from it (remove it to "
                     "start again)");
  }
}

// --resume: go on from the folder's checkpoint, when there is one.
void resume_training(const Args& args, const Console& console, Reconstructor& reconstructor,
                     const std::filesystem::path& checkpoint) {
  if (!args.is_set("resume")) return;
  remove_stale_temporaries(checkpoint.parent_path());  // a SIGKILL mid-write leaves them
  if (!std::filesystem::exists(checkpoint)) {
    console.line("--resume: no " + std::string(kCheckpointName) + " in " +
                 checkpoint.parent_path().string() + ": training from the start");
    return;
  }
  reconstructor.resume_from(checkpoint);
  console.line("resuming the training at step " + std::to_string(reconstructor.steps_done()) +
               " of " + std::to_string(reconstructor.config().training.steps) + " from " +
               checkpoint.string());
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
      .option("format", "EXT",
              "image format: nii, npy, tif, raw or h5 (a volume, dataset /volume); a slabbed "
              "run writes TIFF slices (volume/) and with h5, npy or raw, or nii or tif given, "
              "also gathers them into volume.<format>",
              "nii")
      .option("config", "FILE", "settings JSON ({\"training\": {\"steps\": 4000}, ...})", "")
      .list_option("set", "NAME=VALUE,...",
                   "change settings after --config (training.alpha_lr_scale=0.3; `riner "
                   "settings` lists them); given more than once, all of them in order")
      .option("steps", "N",
              "training steps (default " + std::to_string(TrainingConfig::kSteps2d) +
                  " for a slice, more for a large one so that each ray is drawn " +
                  std::to_string(static_cast<int>(TrainingConfig{}.min_draws_per_ray)) +
                  " times, " + std::to_string(TrainingConfig::kSteps3d) +
                  " or more for a volume so that each voxel is sampled " +
                  std::to_string(static_cast<int>(TrainingConfig{}.min_samples_per_voxel)) +
                  " times; the learning rate falls smoothly to 1/16 over them, or halves every "
                  "quarter of them on a scan with fewer readings than unknowns)",
              "")
      .option("seed", "N", "random seed", "")
      .option("rays-per-step", "N",
              "rays per training step (default: the device's execution plan: 160 on a CPU, "
              "640 on a GPU)",
              "")
      .option("lr", "RATE", "initial learning rate", "")
      .option("report-every", "N", "steps between progress reports", "200")
      .option("checkpoint-minutes", "M",
              "save the training's state to the output folder's training.checkpoint (a "
              "slabbed run: each slab's to slabs/) every M minutes of training (0: never), "
              "from which --resume goes on after a kill",
              "5")
      .flag("paper", "use the paper's settings (L=10, T=2^10, F=8, width 128, 4000 steps, ...)")
      .flag("no-ring-correction",
            "write the trained field and alpha as they are (no ring corrections, no residual "
            "detail)");
  add_slab_options(args);
  add_engine_flags(args);
  args.output_flags();
  if (!args.parse(argc, argv, first)) return 0;
  // The whole run, reading the scan and writing the outputs included: on a big 3D scan the
  // set-up and evaluation take longer than the training.
  const auto started = std::chrono::steady_clock::now();
  Console console(args);
  const int every = report_every(args);  // a bad value said now, not after the set-up
  if (wants_slabs(args)) return reconstruct_by_slabs(args, console, config_from(args), started);
  // Only a slabbed run shares out its work; anything else would run N times into one folder.
  if (SlabRanks::launched_size() > 1) {
    throw UsageError(
        "several processes share only a slabbed run (a projection stack with "
        "--slab-slices or --memory-limit): run this one as one process");
  }
  LoadedScan loaded = scan_from(args, console);
  const std::optional<CentreEstimate> centre_check = check_centre(loaded, console);
  note_missing_lines(console, loaded.scan.geometry);
  note_grid_beyond_rays(console, loaded.scan.geometry);
  note_object_beyond_detector(console, loaded.scan);
  note_unphysical_readings(console, loaded.scan);
  Scan& scan = loaded.scan;
  require_quality_grid(scan.geometry);
  require_memory(scan.geometry);
  const RinerConfig config = config_from(args);
  require_training(config);
  const std::string format = output_format(args);
  if (format == "h5" && !scan.geometry.is_3d()) {
    throw UsageError("--format h5 writes volumes; write a 2D image as nii, npy, tif or raw");
  }
  const std::filesystem::path out = make_output_dir(args.get("out"));
  const FolderLock lock(out);  // before the checkpoint is looked at: a live run may write it
  // Every image format's name: an earlier run's image.nii beside this run's image.npy would
  // pass for this run's.
  std::vector<std::string> outputs = {"image.png",         "alpha.npy",    "beta.npy",
                                      "alpha_by_view.npy", "detector.png", "loss.csv",
                                      "config.json",       "summary.json"};
  for (const char* ext : {"nii", "npy", "tif", "raw", "raw.json", "h5"}) {
    outputs.push_back(std::string("image.") + ext);
  }
  refuse_outputs_over_inputs(out, outputs);
  refuse_overwriting_input(out / kCheckpointName);
  // With the spikes training leaves out as it does NaN (riner/scan.hpp largest_reading), so the
  // count is summary.json's non_finite (before: 360 said, 365 recorded).
  note_non_finite(
      console, scan.non_finite + count_corrupt_readings(scan.measurement, scan.geometry.n_views()));

  const std::optional<Device> device = device_from(args, config.engine);
  const double checkpoint_every = checkpoint_seconds(args);
  const std::filesystem::path checkpoint = out / kCheckpointName;
  refuse_unfinished(args, checkpoint);
  if (std::filesystem::exists(out / "manifest.json")) {
    throw UsageError((out / "manifest.json").string() +
                     ": the folder holds a slabbed run, which a single scan's outputs would mix "
                     "with: choose another output folder");
  }
  if (checkpoint_every > 0.0) catch_stop_signals();
  Reconstructor reconstructor(std::move(scan), config, device);
  resume_training(args, console, reconstructor, checkpoint);
  CheckpointSaver saver(reconstructor, checkpoint, checkpoint_every);
  {
    const TrainingStats setup = reconstructor.stats();
    if (setup.plan) console.line(setup.plan->describe());
    if (config.training.steps == TrainingConfig::kScanSteps &&
        setup.steps_planned >
            config.training.steps_for(reconstructor.scan().geometry.is_3d())) {
      char line[240];
      if (reconstructor.scan().geometry.is_3d()) {
        std::snprintf(line, sizeof(line),
                      "%d steps of %d rays, so that each voxel is sampled %.0f times "
                      "(training.min_samples_per_voxel; --steps N sets the count)",
                      setup.steps_planned, setup.rays_per_step, setup.samples_per_voxel_planned);
      } else {
        std::snprintf(line, sizeof(line),
                      "%d steps of %d rays, so that each of the slice's rays is drawn %.0f "
                      "times (training.min_draws_per_ray; --steps N sets the count)",
                      setup.steps_planned, setup.rays_per_step, setup.draws_per_ray_planned);
      }
      console.line(line);
    }
    if (setup.warm_start) {
      char line[300];
      std::snprintf(line, sizeof(line),
                    "warm start from the '%s' stripe filter (%.1f s): alpha read off the scan "
                    "(mean |ln alpha| %.3f), the field fitted to its FBP (%d steps, mean |error| "
                    "%.2g /mm); then %d steps at learning rate %.2g",
                    setup.warm_start->method.c_str(), setup.warm_start->seconds,
                    setup.warm_start->mean_abs_log_alpha, setup.warm_start->fit_steps,
                    setup.warm_start->fit_residual, setup.steps_planned,
                    reconstructor.config().training.learning_rate);
      console.line(line);
    }
    const std::vector<ChangingElement> changing = reconstructor.changing_elements();
    if (!changing.empty()) {
      const auto dies = std::count_if(changing.begin(), changing.end(),
                                      [](const ChangingElement& c) { return c.dies; });
      console.line("partial rings: " + std::to_string(changing.size() - dies) +
                   " element(s) change response part-way and " + std::to_string(dies) +
                   " die part-way: alpha and beta per segment of views (summary.json "
                   "changing_elements, alpha_by_view.npy)");
    }
    if (setup.air_skipped) {
      char line[240];
      std::snprintf(line, sizeof(line),
                    "skipping the air: %.0f%% of the grid sampled, %.0f%% of the samples kept",
                    100.0 * setup.inside_fraction, 100.0 * setup.samples_kept_fraction);
      console.line(line);
      if (setup.air_outlier_views > 0) {
        console.line("  " + std::to_string(setup.air_outlier_views) +
                     " view(s) read their air off the others' level or noise: they carve nothing");
      }
      if (setup.skipped_rays_near > kNearRaysNoted &&
          static_cast<double>(setup.skipped_rays_near) >
              kNearRaysShareNoted * static_cast<double>(setup.skipped_rays)) {
        std::snprintf(line, sizeof(line),
                      "note: %zu rays through only skipped air beside the object read above air "
                      "(up to %.1f noise sigmas): scatter, or faint matter the carving skipped "
                      "(training.skip_air false samples everything)",
                      setup.skipped_rays_near, setup.skipped_ray_sigmas);
        console.line(line);
      }
    } else if (config.training.skip_air && !setup.air_note.empty()) {
      console.line("not skipping the air: " + setup.air_note);
    }
    note_filled_rows(console, setup.filled_rows);
    note_starved_readings(console, setup.starved_readings, setup.starved_floor);
    if (setup.field_per_mu != 1.0) {
      char line[240];
      std::snprintf(line, sizeof(line),
                    "the readings' attenuation is %.3g /mm, far from the usual 0.001-0.06: the "
                    "field learns it times %g (summary.json field_per_mu)",
                    setup.typical_mu, setup.field_per_mu);
      console.line(line);
    }
  }
  {
    Progress progress("reconstruct",
                      static_cast<std::size_t>(reconstructor.config().training.steps),
                      console.quiet());
    reconstructor.run(
        [&](const TrainingProgress& p) {
          char status[64];
          std::snprintf(status, sizeof(status), "loss %.4g", p.loss);
          progress.update(static_cast<std::size_t>(p.step), status);
          const bool stopping = p.step < p.total && stop_signal() != 0;
          saver.after_report(p, stopping);
          return !stopping;
        },
        every);
    progress.finish();
  }
  release_stop_signals();
  if (reconstructor.steps_done() < reconstructor.config().training.steps && stop_signal() != 0) {
    return stopped_by_signal(std::to_string(reconstructor.steps_done()) + " of " +
                             std::to_string(reconstructor.config().training.steps) +
                             " steps trained, " + checkpoint.string() + " saved");
  }

  const Geometry& g = reconstructor.scan().geometry;
  const ReconstructionResult result = reconstructor.result();
  const Array& image = result.image;
  const Array& alpha = result.alpha;
  const std::filesystem::path image_path = out / ("image." + format);
  clear_previous_outputs(out, outputs);
  write_array(image_path, image, {std::vector<double>(image.rank(), g.voxel_mm)});
  write_png(out / "image.png", image);
  const TrainingStats stats = reconstructor.stats();
  const QualityCheck quality = check_quality(reconstructor, result, device);
  nlohmann::json summary = {{"image", image_path.string()}};
  summary.update(run_summary(reconstructor, result, quality));
  const std::vector<std::size_t> dead = summary["dead_elements"];
  write_detector_outputs(out, alpha, reconstructor.beta(), dead, result.alpha_by_view);
  write_history(out / "loss.csv", reconstructor.history());
  write_text(out / "config.json", reconstructor.config().to_json());  // as resolved for the device

  summary["inputs"] = inputs_json(args);
  summary["flat_field"] =
      loaded.flat_field ? flat_field_json(*loaded.flat_field) : nlohmann::json(nullptr);
  summary["centre"] = loaded.centre ? centre_json(*loaded.centre) : nlohmann::json(nullptr);
  // The scan's own estimate of the axis beside the offset it was given (null: not checked).
  summary["centre_check"] = centre_check ? centre_json(*centre_check) : nlohmann::json(nullptr);
  summary["geometry_doubts"] = loaded.geometry_doubts;
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  summary["wall_seconds"] = wall;  // "seconds" is the training's, before a resume included
  write_text(out / "summary.json", summary.dump(1) + "\n");
  saver.discard();  // the run is done: its outputs stand in for the checkpoint
  console.line("reconstructed " + shape_string(image.shape) + " in " + format_duration(wall) +
               " (training " + format_duration(stats.seconds) + "; " + std::to_string(stats.steps) +
               " steps, " + std::to_string(dead.size()) + " elements flagged dead) -> " +
               out.string());
  note_stopped_hull(console, result.stopped_hull_voxels, result.stopped_hull_mean);
  print_quality_doubts(console, quality.image);
  console.summary(summary);
  return 0;
}

}  // namespace riner::app
