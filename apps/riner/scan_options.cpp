#include "scan_options.hpp"

#include <cmath>
#include <cstdio>

#include <filesystem>

#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/scan.hpp"
#include "riner/tomo_file.hpp"
#include "summary_json.hpp"

namespace riner::app {

void add_scan_options(Args& args) {
  args.positional("SCAN",
                  "the measurement (rho = -ln(I/I0)), or with --flat the raw projections: "
                  ".npy, .nii, .tif, .raw, a folder of TIFFs or a quoted pattern ('raw_*.tif'), "
                  "FILE.h5:/dataset; or a Data Exchange / NXtomo file (.h5, .nxs) with its own "
                  "flats and darks")
      .option("geometry", "FILE",
              "geometry JSON (default: geometry.json beside SCAN; for a folder or pattern, in its "
              "folder or beside it)",
              "")
      .option("flat", "FILE",
              "flat field (beam, no sample): SCAN then holds raw intensities I and riner uses "
              "-ln((I - dark) / (flat - dark)); one frame, or a stack, folder or pattern of "
              "frames (averaged)",
              "")
      .option("dark", "FILE", "dark field (no beam) for --flat, likewise; default: none (0)", "")
      .option("flat-after", "FILE",
              "flats taken after the scan (--flat: before it): each view's flat field is "
              "interpolated between the two, for a beam that drifts during the scan",
              "")
      .option("row", "N", "use detector row N of a projection stack with a 2D geometry (one slice)",
              "")
      .option("offset-px", "PX|auto",
              "the detector's centre-of-rotation offset instead of the geometry's; auto: "
              "estimated from the scan itself as `riner center` does (a parallel beam's whole "
              "sinogram, a fan or cone beam's conjugate rays over a full turn)",
              "");
}

ScanSource source_from(const Args& args) {
  ScanSource source{args.get("SCAN"), args.get("geometry"),
                    args.get("flat"), args.get("dark"),
                    std::nullopt,     args.has("offset-px") ? args.get("offset-px") : "",
                    args.get("flat-after")};
  if (const std::string r = args.get("row"); !r.empty()) {
    const long n = args.integer("row");
    if (n < 0) throw UsageError("--row must be 0 or more");
    source.row = static_cast<std::size_t>(n);
  }
  const bool scan_json = std::filesystem::path(source.path).extension() == ".json";
  if (scan_json && !(source.flat.empty() && source.dark.empty() && source.geometry.empty())) {
    throw UsageError(
        "a scan JSON names its own data and geometry: drop --flat, --dark and "
        "--geometry");
  }
  for (const char* name : {"geometry", "flat", "dark", "flat-after"}) {
    // An unset shell variable ("--dark $DARK") read as no dark field at all.
    if (args.given(name) && args.get(name).empty()) {
      throw UsageError(std::string("--") + name + " needs a file (got an empty name)");
    }
  }
  // A tomography file holds its own flats and darks: one given beside it replaces the file's.
  const bool tomo_file = is_hdf5_path(source.path) && !split_hdf5_dataset(source.path);
  if (!scan_json && !tomo_file && !source.dark.empty() && source.flat.empty()) {
    throw UsageError("--dark needs --flat (and SCAN holding raw projections)");
  }
  if (!tomo_file && !source.flat_after.empty() && source.flat.empty()) {
    throw UsageError("--flat-after needs --flat (the flats before the scan)");
  }
  if (lowercase(source.offset_px) == "auto") source.offset_px = "auto";  // AUTO, Auto
  if (source.offset_px != "auto" && !source.offset_px.empty()) args.number("offset-px");
  return source;
}

nlohmann::json inputs_json(const Args& args) {
  const ScanSource s = source_from(args);
  const auto named = [](const std::string& name) {
    return name.empty() ? nlohmann::json(nullptr) : nlohmann::json(name);
  };
  std::string geometry;  // as read; null where there is none (the run says why)
  try {
    geometry = geometry_file_of(s).string();
  } catch (const InputError&) {
  }
  return {{"scan", s.path},
          {"geometry", named(geometry)},
          {"flat", named(s.flat)},
          {"dark", named(s.dark)},
          {"flat_after", named(s.flat_after)},
          {"row", s.row ? nlohmann::json(*s.row) : nlohmann::json(nullptr)},
          {"offset_px", named(s.offset_px)}};
}

std::optional<Geometry> stack_geometry(const Args& args) {
  if (auto row = args.maybe("row"); row && !row->empty()) return std::nullopt;
  ScanSource source = source_from(args);
  source.offset_px.clear();  // the geometry's size is all that is needed here
  try {
    return ScanRows(source).geometry();
  } catch (const InputError&) {
    return std::nullopt;
  }
}

LoadedScan scan_from(const Args& args, const Console& console, GeometryDoubts doubts) {
  LoadedScan loaded = load_scan_source(source_from(args));
  for (const std::string& note : loaded.notes) console.line(note);
  if (doubts == GeometryDoubts::kWarn) {
    for (const std::string& doubt : loaded.geometry_doubts) console.line("warning: " + doubt);
  }
  return loaded;
}

std::optional<CentreEstimate> check_centre(const LoadedScan& loaded, const Console& console) {
  if (loaded.centre) return std::nullopt;
  std::string note;
  std::optional<CentreEstimate> e = check_geometry_centre(loaded.scan, note);
  if (!note.empty()) console.line("note: " + note);
  return e;
}

}  // namespace riner::app
