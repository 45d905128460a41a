// riner fbp: filtered backprojection (FBP, or FDK for cone beam) of a scan.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <optional>

#include "cli_common.hpp"
#include "commands.hpp"
#include "progress.hpp"
#include "reconstruct_slabs.hpp"
#include "riner/destripe.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/scan.hpp"
#include "riner/slab_fbp.hpp"
#include "riner/slab_plan.hpp"
#include "riner/tomo_file.hpp"
#include "scan_options.hpp"
#include "stopped_beam_note.hpp"
#include "summary_json.hpp"

namespace riner::app {

namespace {

// The slices per slab a GPU's own memory holds (the whole volume on a device that works in
// host memory, or with the reference engine).
std::size_t fbp_device_slices(const Geometry& g, const SlabOptions& asked,
                              const FbpOptions& options) {
  if (options.engine != Engine::kOpenCL || !options.device) return g.volume_shape[0];
  const std::size_t limit = asked.device_limit(options.device->info());
  if (limit == 0) return g.volume_shape[0];
  return fbp_device_slices_within(g, limit, options.device->info().max_alloc_bytes);
}

// A projection stack goes by slabs when asked (--slab-slices, --memory-limit), when the
// output is a folder of slices, or when its volume does not fit in memory whole (the host's,
// or the GPU's).
// `options` (which opens the device) only for a stack that would fit whole.
void note_half_acquisition(const Console& console, double overlap_mm) {
  if (overlap_mm <= 0.0) return;
  char line[200];
  std::snprintf(line, sizeof(line),
                "half acquisition: the axis lies near one end of the detector; conjugate rays "
                "blended over +-%.1f mm around it",
                overlap_mm);
  console.line(line);
}

bool fbp_wants_slabs(const Args& args, const std::function<const FbpOptions&()>& options) {
  const bool asked = !args.get("slab-slices").empty() || !args.get("memory-limit").empty();
  const bool folder = std::filesystem::path(args.get("out")).extension().empty();
  const std::optional<Geometry> g = stack_geometry(args);
  return g && g->is_3d() &&
         (asked || folder || fbp_slab_bytes(*g, g->volume_shape[0]) > default_memory_limit() ||
          !within_piece_size(*g) ||
          fbp_device_slices(*g, SlabOptions{}, options()) < g->volume_shape[0]);
}

// The stripe filter fills every invalid reading from its neighbours; the readings of +inf go back
// where they were after it, so that FBP still tells a beam the object stopped (shown at its
// floor) from a dead element (a review's disc read 1.14 through `--destripe all`, 1.83 without).
Array destripe_keeping_no_light(const Array& measurement, const Geometry& g,
                                const DestripeOptions& options, DestripeReport* report = nullptr) {
  Array out = destripe(measurement, g, options, report);
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (measurement.data[i] == std::numeric_limits<float>::infinity())
      out.data[i] = measurement.data[i];
  }
  return out;
}

// --destripe METHOD: the stripe filter every sinogram goes through first (nullopt: none).
std::optional<DestripeOptions> destripe_from(const Args& args) {
  if (args.get("destripe").empty()) return std::nullopt;
  return destripe_options_from(args, args.get("destripe"));
}

// What a killed earlier write of the output left beside it (a SIGKILL mid-write: riner's
// temporary files whose writer on this host has ended) goes before this one's.
void remove_stale_beside(const std::string& out) {
  std::filesystem::path target = out;
  if (const auto h5 = split_hdf5_dataset(target)) target = h5->first;
  if (target.extension().empty()) remove_stale_temporaries(target);  // a folder of slices
  const std::filesystem::path folder = target.parent_path();
  remove_stale_temporaries(folder.empty() ? "." : folder);
}

// A short scan: weighted (a fan or cone beam over half a turn plus the fan), or missing lines.
void note_short_scan(const Console& console, const FbpReport& report) {
  if (report.parker_weighted) {
    console.line(
        "a short scan (less than a full turn, at least half a turn plus the fan): Parker "
        "weights, each line counted once");
  } else if (report.short_scan) {
    console.line(
        "warning: the views miss part of the circle (a parallel beam's half turn, a fan's half "
        "turn plus the fan): the lines never measured leave streaks");
  }
}

// Readings of +inf where the object stopped the beam: FBP reads them at the floor (the metal
// shows, lighter than it is) or fills them from their neighbours (no metal shows).
void note_stopped_beam(const Console& console, std::size_t readings, float floor) {
  if (readings > 0) console.line("note: " + stopped_beam_note(readings, floor));
}

int fbp_by_slabs_cli(const Args& args, const Console& console, const FbpOptions& options) {
  const ScanRows source(source_from(args));
  const std::vector<std::string> doubts = source.geometry_doubts();
  for (const std::string& note : source.notes()) console.line(note);
  for (const std::string& doubt : doubts) console.line("warning: " + doubt);
  if (source.centre()) console.line(centre_line(*source.centre()));
  const Geometry& g = source.geometry();
  const SlabOptions asked = slab_size_options(args);
  refuse_limit_below_one_slice(asked, fbp_slab_bytes(g, 1));
  const std::size_t limit = asked.limit();
  const std::size_t per =
      asked.slices_per_slab
          ? asked.slices_per_slab
          : std::min({fbp_slices_within(g, limit), fbp_device_slices(g, asked, options),
                      fbp_slices_within_piece_size(g)});
  const std::string out = args.get("out");
  remove_stale_beside(out);
  VolumeWriter writer(out, g.volume_shape, g.voxel_mm);
  const auto start = std::chrono::steady_clock::now();
  const std::size_t nz = g.volume_shape[0];
  Array middle;
  Progress progress("fbp", nz, console.quiet());
  const std::optional<DestripeOptions> stripes = destripe_from(args);
  const SlabFbpReport report = fbp_by_slabs(
      source, options, writer, per,
      [&](std::size_t first, const Array& slices) {
        if (nz / 2 >= first && nz / 2 < first + slices.shape[0]) {
          middle = axial_slice(slices, nz / 2 - first);
        }
        progress.update(first + slices.shape[0]);
      },
      [&](Scan& rows) {
        if (stripes) {
          rows.measurement = destripe_keeping_no_light(rows.measurement, rows.geometry, *stripes);
        }
      });
  writer.close();
  progress.finish();
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (args.is_set("png")) {
    std::filesystem::path png = out;
    png = png.extension().empty() ? png / "middle_slice.png" : png.replace_extension(".png");
    write_png(png, middle);
  }
  if (report.flat_field) {
    for (const std::string& line : flat_field_notes(*report.flat_field)) console.line(line);
  }
  if (report.slices_without_readings > 0) {
    console.line(std::to_string(report.slices_without_readings) +
                 " slice(s) written as NaN: their detector rows read nothing to reconstruct (a "
                 "dead row?)");
  }
  note_short_scan(console, report.fbp);
  note_stopped_beam(console, report.fbp.stopped_beam_readings, report.fbp.stopped_beam_floor);
  note_half_acquisition(console, report.fbp.half_acquisition_overlap_mm);
  note_grid_beyond_rays(console, g);
  console.line("fbp (" + std::string(fbp_filter_name(options.filter)) + ", " +
               engine_name(options.engine) + "): " + shape_string(g.volume_shape) + " in " +
               std::to_string(report.slabs) + " slab(s) of up to " +
               std::to_string(report.slices_per_slab) + " slices in " + std::to_string(seconds) +
               " s, " + std::to_string(report.fbp.non_finite_replaced) +
               " non-finite or absurd (spikes far beyond the other views' readings) measurements "
               "interpolated -> " +
               out);
  nlohmann::json summary = fbp_report_json(report.fbp);
  summary.update(
      {{"out", out},
       {"shape", g.volume_shape},
       {"filter", fbp_filter_name(options.filter)},
       {"engine", engine_name(options.engine)},
       {"seconds", seconds},
       {"slabs", report.slabs},
       {"slices_per_slab", report.slices_per_slab},
       {"memory_limit_bytes", limit},
       {"slab_bytes_estimated", fbp_slab_bytes(g, report.slices_per_slab)},
       {"geometry_doubts", doubts},
       {"inputs", inputs_json(args)},
       {"flat_field",
        report.flat_field ? flat_field_json(*report.flat_field) : nlohmann::json(nullptr)},
       {"slices_without_readings", report.slices_without_readings},
       {"centre", source.centre() ? centre_json(*source.centre()) : nlohmann::json(nullptr)}});
  console.summary(summary);
  return 0;
}

}  // namespace

int run_fbp(int argc, char** argv, int first) {
  Args args("fbp",
            "Filtered backprojection of a scan: FBP for parallel and fan beam, FDK for cone "
            "beam. NaN/inf measurements (dead elements) are interpolated from their neighbours "
            "first; +inf where the object stopped the beam (metal), beside its edge, reads as "
            "the largest finite reading of nine views in ten (of its detector row). The image is "
            "written in the format of --out's extension.");
  add_scan_options(args);
  args.option("out", "IMAGE",
              "output image/volume (.nii, .npy, .tif, .raw), a volume as FILE.h5[:/dataset] "
              "(default dataset /volume), or a folder (no extension) of one TIFF per slice")
      .option("filter", "NAME", "ram-lak, shepp-logan or hann", "ram-lak")
      .flag("png", "also write a PNG preview beside the output")
      .flag("fill-stopped-beam",
            "readings of +inf where the object stopped the beam (metal) interpolated from their "
            "neighbours, as other invalid readings are, not read as their row's floor: no metal "
            "(and no metal streaks) in the image")
      .option("slab-slices", "N",
              "a projection stack (parallel or cone beam) in slabs of up to N axial slices (evened "
              "out: 16 slices at N=5 are 4 slabs of 4), each read, "
              "reconstructed and written alone (default: as many as --memory-limit allows)",
              "")
      .option("memory-limit", "SIZE",
              "memory a slab may take, on the host and on a GPU (8G, 512M); a stack whose "
              "volume does not fit goes by slabs; one below a slab of one slice is refused "
              "(default: three quarters of the machine's memory, nine tenths of a GPU's)",
              "")
      .option("destripe", "METHOD",
              "remove stripes from every sinogram first (riner destripe's methods: normalise, "
              "sorting, filtering, fitting, wavelet, large, dead, all)",
              "");
  add_destripe_tuning(args);
  add_engine_flags(args);
  args.output_flags();
  if (!args.parse(argc, argv, first)) return 0;
  Console console(args);
  // A PNG is an 8-bit preview, not the image: it was written as "the result" with exit 0.
  if (lowercase(std::filesystem::path(args.get("out")).extension().string()) == ".png") {
    throw UsageError(args.get("out") +
                     ": a PNG is an 8-bit preview; write the image as .nii, .npy, .tif, .raw or "
                     ".h5 and add --png for a preview beside it");
  }
  // Made once, when first needed: an unreadable scan is reported before a bad option.
  std::optional<FbpOptions> made;
  const auto fbp_options = [&]() -> const FbpOptions& {
    if (!made) {
      FbpOptions options;
      options.filter = parse_fbp_filter(args.get("filter"));
      options.stopped_beam_at_floor = !args.is_set("fill-stopped-beam");
      options.engine = engine_from(args);
      options.device = device_from(args, options.engine);
      made = std::move(options);
    }
    return *made;
  };
  if (fbp_wants_slabs(args, fbp_options)) return fbp_by_slabs_cli(args, console, fbp_options());
  LoadedScan loaded = scan_from(args, console);
  check_centre(loaded, console);
  Scan scan = std::move(loaded.scan);  // the stripe filter may replace its measurement
  const std::filesystem::path out = args.get("out");
  format_from_path(out);  // reject an unknown extension before the work
  remove_stale_beside(out.string());
  const FbpOptions& options = fbp_options();
  const std::optional<DestripeOptions> stripes = destripe_from(args);
  if (stripes) {
    DestripeReport destripe_report;
    scan.measurement =
        destripe_keeping_no_light(scan.measurement, scan.geometry, *stripes, &destripe_report);
    console.line("destripe (" + std::string(destripe_method_name(stripes->method)) + "): " +
                 std::to_string(destripe_report.dead.size()) + " dead and " +
                 std::to_string(destripe_report.large.size()) + " large-stripe elements found");
    note_large_stripes(console, destripe_report);
  }
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
  note_short_scan(console, report);
  note_stopped_beam(console, report.stopped_beam_readings, report.stopped_beam_floor);
  note_half_acquisition(console, report.half_acquisition_overlap_mm);
  note_grid_beyond_rays(console, scan.geometry);
  note_object_beyond_detector(console, scan);
  console.line("fbp (" + std::string(fbp_filter_name(options.filter)) + ", " +
               engine_name(options.engine) + "): " + shape_string(image.shape) + " in " +
               std::to_string(seconds) + " s, " + std::to_string(report.non_finite_replaced) +
               " non-finite or absurd (spikes far beyond the other views' readings) measurements "
               "interpolated -> " +
               out.string());
  nlohmann::json summary = fbp_report_json(report);
  summary.update(
      {{"out", out.string()},
       {"shape", image.shape},
       {"filter", fbp_filter_name(options.filter)},
       {"engine", engine_name(options.engine)},
       {"seconds", seconds},
       {"destripe",
        stripes ? nlohmann::json(destripe_method_name(stripes->method)) : nlohmann::json(nullptr)},
       {"geometry_doubts", loaded.geometry_doubts},
       {"inputs", inputs_json(args)},
       {"flat_field",
        loaded.flat_field ? flat_field_json(*loaded.flat_field) : nlohmann::json(nullptr)},
       {"centre", loaded.centre ? centre_json(*loaded.centre) : nlohmann::json(nullptr)}});
  console.summary(summary);
  return 0;
}

}  // namespace riner::app
