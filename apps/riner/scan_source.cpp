#include "scan_source.hpp"

#include <cstdio>
#include <cstdlib>

#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/tomo_file.hpp"

namespace riner::app {

namespace {

bool is_tomo_file(const std::string& path) {
  return is_hdf5_path(path) && !split_hdf5_dataset(path);
}

// A scan JSON's "files" replace the path, flat and dark; the JSON is the geometry.
void resolve_scan_json(ScanSource& source) {
  const std::optional<ScanFiles> files = read_scan_files(source.path);
  if (!files) {
    throw InputError(source.path +
                     ": a geometry without \"files\"; give the measurement as SCAN and this "
                     "file as the geometry, or name the data in \"files\"");
  }
  if (!source.flat.empty() || !source.dark.empty() || !source.geometry.empty()) {
    throw InputError(
        "a scan JSON names its own data and geometry: give no flat, dark or "
        "geometry with it");
  }
  source.geometry = source.path;
  source.path = (files->measurement.empty() ? files->projections : files->measurement).string();
  source.flat = files->flat.string();
  source.dark = files->dark.string();
  if (!files->projections.empty() && source.flat.empty() && !is_tomo_file(source.path)) {
    throw InputError(source.geometry +
                     ": files.projections needs files.flat (raw intensities are normalised "
                     "by it), unless it is a Data Exchange or NXtomo file");
  }
}

double parse_offset(const std::string& text) {
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0') {
    throw InputError("the centre offset must be a number of pixels or auto (got '" + text + "')");
  }
  return value;
}

}  // namespace

LoadedScan load_scan_source(ScanSource source) {
  if (std::filesystem::path(source.path).extension() == ".json") resolve_scan_json(source);
  if (!source.dark.empty() && source.flat.empty() && !is_tomo_file(source.path)) {
    throw InputError("a dark field needs a flat field (and SCAN holding raw projections)");
  }
  LoadedScan loaded;
  FlatFieldReport report;
  if (source.flat.empty() && is_tomo_file(source.path)) {
    // A tomography file holds its own flats and darks.
    if (!source.dark.empty()) throw InputError("a tomography file brings its own dark field");
    const TomoFile file = read_tomo_file(source.path);
    if (file.flats.shape.empty()) {
      throw InputError(source.path + ": the file holds no flat field (" + file.layout +
                       "); pass one with --flat");
    }
    loaded.scan =
        raw_scan(Geometry::load(find_geometry(source.path, source.geometry)), file.projections,
                 file.flats, file.darks, source.row, source.path, &report);
    loaded.flat_field = report;
    loaded.notes.push_back(file.layout + " file: " + flat_field_line(report));
  } else if (source.flat.empty()) {
    loaded.scan = load_scan(source.path, source.geometry, source.row);
  } else {
    loaded.scan =
        load_raw_scan(source.path, source.flat, source.dark, source.geometry, &report, source.row);
    loaded.flat_field = report;
    loaded.notes.push_back(flat_field_line(report));
  }
  if (source.offset_px == "auto") {
    loaded.centre = estimate_centre(loaded.scan);
    loaded.scan.geometry.offset_u = loaded.centre->offset_px;
    loaded.notes.push_back(centre_line(*loaded.centre));
  } else if (!source.offset_px.empty()) {
    loaded.scan.geometry.offset_u = parse_offset(source.offset_px);
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
  char line[320];
  if (e.method == "sinogram") {
    std::snprintf(line, sizeof(line),
                  "centre of rotation: offset %.2f px (axis at column %.2f) from the whole "
                  "sinogram over %zu row(s)",
                  e.offset_px, e.axis_column, e.rows);
    std::string out = line;
    if (e.pairs > 0) {
      std::snprintf(line, sizeof(line), "; view pairs say %.2f px (spread %.2f over %zu pairs)",
                    e.pairs_offset_px, e.spread_px, e.pairs);
      out += line;
    }
    return out;
  }
  std::snprintf(line, sizeof(line),
                "centre of rotation: offset %.2f px (axis at column %.2f), spread %.2f px over "
                "%zu view pair(s) x %zu row(s)",
                e.offset_px, e.axis_column, e.spread_px, e.pairs, e.rows);
  return line;
}

}  // namespace riner::app
