#include "scan_options.hpp"

#include <cstdio>

#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/tomo_file.hpp"

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
      .option("row", "N",
              "reconstruct detector row N of a projection stack with a 2D geometry (one slice)", "")
      .option("offset-px", "PX|auto",
              "the detector's centre-of-rotation offset instead of the geometry's; auto: "
              "estimated from views half a turn apart (parallel beam, `riner center`)",
              "");
}

LoadedScan scan_from(const Args& args, const Console& console) {
  const std::string flat = args.get("flat");
  const std::string dark = args.get("dark");
  const std::string path = args.get("SCAN");
  std::optional<std::size_t> row;
  if (const std::string r = args.get("row"); !r.empty()) {
    const long n = args.integer("row");
    if (n < 0) throw UsageError("--row must be 0 or more");
    row = static_cast<std::size_t>(n);
  }
  LoadedScan loaded;
  FlatFieldReport report;
  if (flat.empty() && is_hdf5_path(path) && !split_hdf5_dataset(path)) {
    // A tomography file holds its own flats and darks.
    if (!dark.empty()) throw UsageError("--dark needs --flat");
    const TomoFile file = read_tomo_file(path);
    if (file.flats.shape.empty()) {
      throw InputError(path + ": the file holds no flat field (" + file.layout +
                       "); pass one with --flat");
    }
    loaded.scan = raw_scan(Geometry::load(find_geometry(path, args.get("geometry"))),
                           file.projections, file.flats, file.darks, row, path, &report);
    loaded.flat_field = report;
    console.line(file.layout + " file: " + flat_field_line(report));
  } else if (flat.empty()) {
    if (!dark.empty()) throw UsageError("--dark needs --flat (and SCAN holding raw projections)");
    loaded.scan = load_scan(path, args.get("geometry"), row);
  } else {
    loaded.scan = load_raw_scan(path, flat, dark, args.get("geometry"), &report, row);
    loaded.flat_field = report;
    console.line(flat_field_line(report));
  }
  if (args.has("offset-px")) {
    const std::string offset = args.get("offset-px");
    if (offset == "auto") {
      loaded.centre = estimate_centre(loaded.scan);
      loaded.scan.geometry.offset_u = loaded.centre->offset_px;
      console.line(centre_line(*loaded.centre));
    } else if (!offset.empty()) {
      loaded.scan.geometry.offset_u = args.number("offset-px");
    }
  }
  return loaded;
}

std::string flat_field_line(const FlatFieldReport& r) {
  return "raw projections: flat field of " + std::to_string(r.flat_frames) + " frame(s), " +
         (r.dark_frames ? "dark field of " + std::to_string(r.dark_frames) + " frame(s)"
                        : std::string("no dark field")) +
         "; " + std::to_string(r.invalid_readings) +
         " readings invalid (at or below the dark, or on " + std::to_string(r.pixels_without_beam) +
         " pixels without beam)";
}

std::string centre_line(const CentreEstimate& e) {
  char line[200];
  std::snprintf(line, sizeof(line),
                "centre of rotation: offset %.2f px (axis at column %.2f), spread %.2f px over "
                "%zu view pair(s) x %zu row(s)",
                e.offset_px, e.axis_column, e.spread_px, e.pairs, e.rows);
  return line;
}

}  // namespace riner::app
