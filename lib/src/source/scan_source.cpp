#include "riner/scan_source.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>

#include "io/stack.hpp"
#include "riner/error.hpp"
#include "riner/flat_field.hpp"
#include "riner/geometry_doubts.hpp"
#include "riner/io.hpp"
#include "riner/rays.hpp"
#include "riner/tomo_file.hpp"

namespace riner {

namespace {

bool is_tomo_file(const std::string& path) {
  return is_hdf5_path(path) && !split_hdf5_dataset(path);
}

// Where SCAN is a scan JSON, its "files" replace the path, flat and dark, and the JSON is the
// geometry; any other SCAN is left as it is.
void resolve_scan_json(ScanSource& source) {
  if (std::filesystem::path(source.path).extension() != ".json") return;
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
  source.flat_after = files->flat_after.string();
  if (!files->projections.empty() && source.flat.empty() && !is_tomo_file(source.path)) {
    throw InputError(source.geometry +
                     ": files.projections needs files.flat (raw intensities are normalised "
                     "by it), unless it is a Data Exchange or NXtomo file");
  }
}

// Frames of a flat or dark field (one frame [rows, cols] or a stack [frames, rows, cols]), only
// rows `rows` of each.
Array frames_rows(const std::filesystem::path& path, RowRange rows) {
  const std::vector<std::size_t> shape = read_array_shape(path);
  if (shape.size() == 3) return read_array_rows(path, rows).array;
  if (shape.size() != 2) {
    throw InputError(path.string() + ": is " + shape_string(shape) +
                     "; a flat or dark field is one frame or a stack of frames");
  }
  Array frame = read_array(path).array;
  frame.shape.insert(frame.shape.begin(), 1);
  Array cut = detector_rows(frame, rows);
  cut.shape.erase(cut.shape.begin());
  return cut;
}

// What `name` reads: per file, a key (its canonical path; an HDF5 dataset's with the dataset: a
// file's flats beside its projections are no overlap) and the name to show.
std::map<std::string, std::string> files_read(const std::string& name) {
  const auto key = [](const std::filesystem::path& file) {
    std::error_code ignored;
    const std::filesystem::path canonical = std::filesystem::weakly_canonical(file, ignored);
    return (canonical.empty() ? file : canonical).string();
  };
  if (name.empty()) return {};
  if (const auto h5 = split_hdf5_dataset(name)) return {{key(h5->first) + ":" + h5->second, name}};
  if (is_tomo_file(name)) return {};  // a tomography file: its own flats, darks or projections
  if (!io::is_stack_path(name)) return {{key(name), name}};
  std::map<std::string, std::string> out;
  try {
    for (const std::filesystem::path& file : io::stack_files(name)) out.emplace(key(file), file);
  } catch (const InputError&) {
    return {};  // no such files: reading them says so, in its own words
  }
  return out;
}

// One file read as two things: a pattern matching another's files ('flat_*.tif' matches the
// 'flat_end_*.tif' of --flat-after: an audit's drift then read +4.8% for +10%, without a word).
// The same flats before and after the scan are no such mistake: no drift.
void check_no_file_twice(const ScanSource& source) {
  const std::map<std::string, std::string> flats = files_read(source.flat);
  std::map<std::string, std::string> flats_after = files_read(source.flat_after);
  if (flats_after == flats) flats_after.clear();
  const std::pair<std::map<std::string, std::string>, const char*> fields[] = {
      {files_read(source.path), "the scan"},
      {flats, "the flat field"},
      {files_read(source.dark), "the dark field"},
      {std::move(flats_after), "the flat field after the scan"}};
  std::map<std::string, const char*> seen;
  for (const auto& [files, what] : fields) {
    for (const auto& [file, shown] : files) {
      const auto [at, fresh] = seen.emplace(file, what);
      if (!fresh && at->second != what) {
        throw InputError(shown + " is read as " + at->second + " and as " + what +
                         ": make the file patterns exclusive");
      }
    }
  }
}

// Resolves a scan JSON into its files and checks the flat and dark fit SCAN; true when SCAN is
// a tomography file, which holds its own flats and darks (a flat, dark or flats-after field
// given beside it replaces or adds to the file's own).
bool resolve_files(ScanSource& source) {
  resolve_scan_json(source);
  const bool tomo_file = is_tomo_file(source.path);
  if (!source.dark.empty() && source.flat.empty() && !tomo_file) {
    throw InputError("a dark field needs a flat field (and SCAN holding raw projections)");
  }
  if (!source.flat_after.empty() && source.flat.empty() && !tomo_file) {
    throw InputError("flats after the scan need the flats before them");
  }
  check_no_file_twice(source);
  return tomo_file;
}

enum class Field { kFlat, kDark };

// A field's frames (of `shape`) must be one frame of a view's shape or a stack of them: said
// naming the field's file (it named the scan, or nothing for the flats after it).
void check_field_shape(const std::vector<std::size_t>& shape, const std::vector<std::size_t>& view,
                       const std::string& path, const char* what) {
  const bool one = shape == view;
  const bool stack = shape.size() == view.size() + 1 && shape[0] > 0 &&
                     std::equal(view.begin(), view.end(), shape.begin() + 1);
  if (!one && !stack) {
    throw InputError(path + ": " + what + " of shape " + shape_string(shape) +
                     " is neither one frame of a view's shape " + shape_string(view) +
                     " nor a stack of them");
  }
}

Array checked_field(Array frames, const std::vector<std::size_t>& projections,
                    const std::string& path, const char* what) {
  check_field_shape(frames.shape, {projections.begin() + 1, projections.end()}, path, what);
  return frames;
}

// A flat or dark field's frames from `path` (only rows `rows` of each, when set). A tomography
// file gives its own flats or darks: read as an array it gave its projections, which passed as
// a flat field of 90 frames.
// Checked against the projections' shape: named by its own file.
Array field_frames(const std::string& path, Field field, std::optional<RowRange> rows,
                   const std::vector<std::size_t>& projections, const char* what) {
  if (is_tomo_file(path)) {
    TomoFile file = read_tomo_file(path, rows);
    Array& frames = field == Field::kFlat ? file.flats : file.darks;
    if (frames.shape.empty()) {
      throw InputError(path + ": the file holds no " + (field == Field::kFlat ? "flat" : "dark") +
                       " field (" + file.layout + ")");
    }
    return checked_field(std::move(frames), projections, path, what);
  }
  return checked_field(rows ? frames_rows(path, *rows) : read_array(path).array, projections, path,
                       what);
}

// Raw projections (`frames.projections`, as stored: `frames.dtype`) with their flat and dark
// fields: each given beside the scan, or else the tomography file's own (none in `frames` for
// other files); flats after the scan added to them. Rows `rows` of each field, when set.
Scan raw_frames_scan(const ScanSource& source, Geometry g, TomoFile frames,
                     std::optional<RowRange> rows, std::optional<std::size_t> row,
                     FlatFieldReport* report) {
  const std::vector<std::size_t>& shape = frames.projections.shape;
  Array flats = source.flat.empty()
                    ? std::move(frames.flats)
                    : field_frames(source.flat, Field::kFlat, rows, shape, "the flat field");
  std::vector<double> positions =
      source.flat.empty() ? frames.flat_positions : std::vector<double>{};
  if (flats.shape.empty()) {
    throw InputError(source.path + ": the file holds no flat field (" + frames.layout +
                     "); pass one with --flat");
  }
  const Array darks = source.dark.empty()
                          ? std::move(frames.darks)
                          : field_frames(source.dark, Field::kDark, rows, shape, "the dark field");
  if (!source.flat_after.empty()) {
    const std::size_t series_before = positions.size();
    FlatStack both = flats_before_after(
        flats,
        field_frames(source.flat_after, Field::kFlat, rows, shape, "the flat field after the scan"),
        shape);
    // The file's own series keep their places among the views; those after the scan follow.
    if (series_before > 0) {
      std::copy(positions.begin(), positions.end(), both.positions.begin());
    }
    flats = std::move(both.frames);
    positions = std::move(both.positions);
  }
  const std::size_t saturated = mark_saturated(frames.projections, frames.dtype);
  Scan scan =
      raw_scan(std::move(g), frames.projections, flats, darks, row, source.path, report, positions);
  if (report) report->saturated_readings = saturated;
  return scan;
}

// Raw projections in an array file (rows `rows`, when set), as raw_frames_scan takes them.
TomoFile raw_array_frames(const std::string& path, std::optional<RowRange> rows) {
  ArrayFile file = rows ? read_array_rows(path, *rows) : read_array(path);
  TomoFile frames;
  frames.projections = std::move(file.array);
  frames.dtype = file.dtype;
  return frames;
}

// A tomography file's projections with its own flats and darks, each replaced by a field given
// beside it, and flats after the scan added to them; its layout and the angles it states.
struct TomoScan {
  Scan scan;
  std::string layout;
  std::vector<double> angles_deg;
};

TomoScan tomo_scan(const ScanSource& source, Geometry g, std::optional<RowRange> rows,
                   std::optional<std::size_t> row, FlatFieldReport* report) {
  TomoFile file = read_tomo_file(source.path, rows);
  const std::string left_out =
      file.frames_left_out == 0
          ? ""
          : std::to_string(file.frames_left_out) +
                " frame(s) neither projection, flat nor dark (image_key 3 or an alignment "
                "frame) left out";
  TomoScan out;
  out.layout = file.layout + (left_out.empty() ? "" : " (" + left_out + ")");
  out.angles_deg = file.angles_deg;
  try {
    out.scan = raw_frames_scan(source, std::move(g), std::move(file), rows, row, report);
  } catch (const InputError& e) {
    if (left_out.empty()) throw;
    throw InputError(std::string(e.what()) + " (" + left_out + ")");
  }
  return out;
}

// Marks the files `name` reads as inputs (a stack's files and its folder; an HDF5 dataset's
// file), so that no output replaces them.
void register_input_files(const std::string& name) {
  if (name.empty()) return;
  if (const auto h5 = split_hdf5_dataset(name)) {
    register_input(h5->first);
  } else if (io::is_stack_path(name)) {
    if (std::filesystem::is_directory(name)) register_input(name);
    for (const std::filesystem::path& file : io::stack_files(name)) register_input(file);
  } else {
    register_input(name);
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

std::string file_angles_note(const std::string& path, const std::vector<double>& angles_deg,
                             const Geometry& g) {
  if (angles_deg.size() < 2 || angles_deg.size() != g.n_views() || g.angles.size() < 2) return "";
  const auto [low, high] = std::minmax_element(angles_deg.begin(), angles_deg.end());
  const auto [first, last] = std::minmax_element(g.angles.begin(), g.angles.end());
  const double file_span = *high - *low;
  const double span = (*last - *first) * 180.0 / M_PI;
  const double step = span / static_cast<double>(g.n_views() - 1);
  const double tolerance = std::max(2.0, 0.02 * span) + step;  // an endpoint counted or not
  if (std::fabs(file_span - span) <= tolerance ||
      std::fabs(file_span * 180.0 / M_PI - span) <= tolerance) {  // the file's in radians
    return "";
  }
  char line[400];
  std::snprintf(line, sizeof(line),
                "note: %s states angles spanning %.1f degrees over its %zu views, the geometry "
                "%.1f: riner takes the geometry's; check them",
                path.c_str(), file_span, angles_deg.size(), span);
  return line;
}

LoadedScan load_scan_source(ScanSource source) {
  const bool tomo_file = resolve_files(source);
  LoadedScan loaded;
  FlatFieldReport report;
  std::string layout;  // a tomography file's, before its flat field's line
  if (tomo_file) {
    TomoScan read = tomo_scan(source, Geometry::load(find_geometry(source.path, source.geometry)),
                              std::nullopt, source.row, &report);
    loaded.scan = std::move(read.scan);
    loaded.flat_field = report;
    layout = read.layout + " file: ";
    if (std::string note = file_angles_note(source.path, read.angles_deg, loaded.scan.geometry);
        !note.empty()) {
      loaded.notes.push_back(std::move(note));
    }
  } else if (source.flat.empty()) {
    loaded.scan = load_scan(source.path, source.geometry, source.row);
    if (std::optional<std::string> note = transmission_note(loaded.scan)) {
      loaded.notes.push_back(std::move(*note));
    }
    if (std::optional<std::string> note = negative_readings_note(loaded.scan)) {
      loaded.notes.push_back(std::move(*note));
    }
  } else {
    loaded.scan = raw_frames_scan(
        source, Geometry::load(find_geometry(source.path, source.geometry)),
        raw_array_frames(source.path, std::nullopt), std::nullopt, source.row, &report);
    loaded.flat_field = report;
  }
  if (std::optional<std::string> why = uniform_readings(loaded.scan)) {
    throw InputError(source.path + ": " + *why);
  }
  if (loaded.flat_field) {
    std::vector<std::string> notes = flat_field_notes(*loaded.flat_field);
    notes.front() = layout + notes.front();
    loaded.notes.insert(loaded.notes.end(), notes.begin(), notes.end());
  }
  if (source.offset_px == "auto") {
    loaded.centre = estimate_centre(loaded.scan);
    loaded.scan.geometry.offset_u = loaded.centre->offset_px;
    loaded.notes.push_back(centre_line(*loaded.centre));
  } else if (!source.offset_px.empty()) {
    loaded.scan.geometry.offset_u = parse_offset(source.offset_px);
  }
  // After the offset: a fan's conjugates are read about the axis the run will use.
  loaded.geometry_doubts = geometry_doubts(loaded.scan);
  return loaded;
}

std::filesystem::path geometry_file_of(ScanSource source) {
  resolve_scan_json(source);
  return find_geometry(source.path, source.geometry);
}

namespace {

// `count` rows to read a stack's centre or geometry doubts from: a cone's about its source's
// plane (its conjugate rays lie there; a band of rows cut off the middle has it elsewhere),
// else the middle ones.
RowRange reading_rows(const Geometry& g, std::size_t most) {
  const std::size_t count = std::min(most, g.n_v);
  if (g.type != GeometryType::kCone3d) return {(g.n_v - count) / 2, count};
  const double first = project_to_detector(g, 0, Vec3{0.0, 0.0, 0.0}).v - 0.5 * (count - 1.0);
  const double last_first = static_cast<double>(g.n_v - count);
  return {static_cast<std::size_t>(std::clamp(std::round(first), 0.0, last_first)), count};
}

}  // namespace

ScanRows::ScanRows(ScanSource source) : source_(std::move(source)) {
  tomo_file_ = resolve_files(source_);
  // Slabs read their rows late: outputs opened before then must already see the inputs.
  for (const std::string* name :
       {&source_.path, &source_.flat, &source_.dark, &source_.flat_after}) {
    register_input_files(*name);
  }
  if (source_.row) throw InputError("a single detector row is read whole: no slabs needed");
  geometry_ = Geometry::load(find_geometry(source_.path, source_.geometry));
  shape_ = read_array_shape(source_.path);
  geometry_ = geometry_for_shape(geometry_, shape_);
  if (!geometry_.is_3d()) {
    throw InputError(source_.path + ": the geometry is " + geometry_type_name(geometry_.type) +
                     "; slabs of detector rows need a 3D geometry");
  }
  geometry_.check_measurement_shape(shape_, source_.path);
  if (tomo_file_) {
    if (std::string note =
            file_angles_note(source_.path, tomo_file_angles(source_.path), geometry_);
        !note.empty()) {
      notes_.push_back(std::move(note));
    }
  }
  // Slabs read the fields' rows late: their frames checked now, not after slabs are written.
  for (const auto& [name, what] :
       {std::pair{&source_.flat, "the flat field"}, std::pair{&source_.dark, "the dark field"},
        std::pair{&source_.flat_after, "the flat field after the scan"}}) {
    if (!name->empty())
      check_field_shape(read_array_shape(*name), {shape_[1], shape_[2]}, *name, what);
  }
  if (source_.offset_px == "auto") {
    centre_ = estimate_centre(read(reading_rows(geometry_, kCentreRows)));
    geometry_.offset_u = centre_->offset_px;
  } else if (!source_.offset_px.empty()) {
    geometry_.offset_u = parse_offset(source_.offset_px);
  }
}

std::vector<std::string> ScanRows::geometry_doubts() const {
  try {
    return riner::geometry_doubts(read(reading_rows(geometry_, kRangeRows)));
  } catch (const InputError&) {
    return {};  // rows that read nothing: the slabs say so in their own words
  }
}

Scan ScanRows::read(RowRange rows, FlatFieldReport* report) const {
  const Geometry g = detector_rows_geometry(geometry_, rows.first, rows.count);
  if (tomo_file_) return tomo_scan(source_, g, rows, std::nullopt, report).scan;
  if (!source_.flat.empty()) {
    return raw_frames_scan(source_, g, raw_array_frames(source_.path, rows), rows, std::nullopt,
                           report);
  }
  ArrayFile file = read_array_rows(source_.path, rows);
  Scan scan;
  scan.geometry = g;
  scan.measurement = std::move(file.array);
  scan.non_finite = file.non_finite;
  check_scan(scan, source_.path);
  return scan;
}

std::vector<std::string> flat_field_notes(const FlatFieldReport& report) {
  std::vector<std::string> notes{flat_field_line(report)};
  for (std::string note : {saturation_line(report), pixels_without_beam_line(report),
                           air_level_line(report), air_drift_line(report)}) {
    if (!note.empty()) notes.push_back(std::move(note));
  }
  return notes;
}

std::string flat_field_line(const FlatFieldReport& r) {
  char series[120] = "";
  if (r.flat_series > 1) {
    std::snprintf(series, sizeof(series),
                  " in %zu series interpolated by view (the beam %+.2f%% from first to last)",
                  r.flat_series, 100.0 * r.flat_change);
  }
  char below[160] = "at or below the dark";
  if (r.dark_noise > 0.0) {
    std::snprintf(below, sizeof(below),
                  "no more light than %.0f times the dark's noise, %.3g, of which %zu above the "
                  "dark",
                  kDarkNoiseSigmas, r.dark_noise, r.readings_in_dark_noise);
  }
  return "raw projections: flat field of " + std::to_string(r.flat_frames) + " frame(s)" + series +
         ", " +
         (r.dark_frames ? "dark field of " + std::to_string(r.dark_frames) + " frame(s)"
                        : std::string("no dark field")) +
         "; " + std::to_string(r.invalid_readings) + " readings invalid (" + below + "; or on " +
         std::to_string(r.pixels_without_beam) + " pixels without beam)";
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
  if (e.method.rfind("conjugate rays", 0) == 0) {
    std::snprintf(line, sizeof(line),
                  "centre of rotation: offset %.2f px (axis at column %.2f) from %zu conjugate "
                  "ray pairs of the full turn%s",
                  e.offset_px, e.axis_column, e.pairs,
                  e.half_acquisition ? "; a half acquisition: the axis near one end of the detector"
                                     : "");
    return line;
  }
  std::snprintf(line, sizeof(line),
                "centre of rotation: offset %.2f px (axis at column %.2f), spread %.2f px over "
                "%zu view pair(s) x %zu row(s)%s",
                e.offset_px, e.axis_column, e.spread_px, e.pairs, e.rows,
                e.half_acquisition ? "; a half acquisition: the axis near one end of the detector"
                                   : "");
  return line;
}

}  // namespace riner
