#include "riner/scan.hpp"

#include <nlohmann/json.hpp>

#include "io/file_access.hpp"
#include "io/stack.hpp"

#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/tomo_file.hpp"

namespace riner {

void check_scan(const Scan& scan, std::string_view what) {
  scan.geometry.check_measurement_shape(scan.measurement.shape, what);
  if (scan.measurement.size() > 0 && scan.non_finite >= scan.measurement.size()) {
    throw InputError(std::string(what) + ": all " + std::to_string(scan.measurement.size()) +
                     " values are NaN or infinite; there is nothing to reconstruct");
  }
}

std::filesystem::path find_geometry(const std::filesystem::path& measurement,
                                    const std::filesystem::path& geometry) {
  if (const auto named = split_hdf5_dataset(measurement)) {
    return find_geometry(named->first, geometry);
  }
  if (!io::is_stack_path(measurement)) {
    io::input_file_size(measurement);  // a missing scan is the first thing to report
  }
  if (!geometry.empty()) return geometry;
  std::vector<std::filesystem::path> folders;
  if (io::is_stack_path(measurement)) {
    std::filesystem::path folder = measurement;
    if (folder.filename().empty()) folder = folder.parent_path();               // "tiffs/"
    if (!std::filesystem::is_directory(folder)) folder = folder.parent_path();  // a pattern
    folders = {folder, folder.parent_path()};
  } else {
    folders = {measurement.parent_path()};
  }
  for (const std::filesystem::path& folder : folders) {
    const std::filesystem::path candidate = folder / "geometry.json";
    if (std::filesystem::exists(candidate)) return candidate;
  }
  throw InputError(measurement.string() +
                   ": no geometry given and no geometry.json beside it (use --geometry)");
}

Scan load_scan(const std::filesystem::path& measurement, const std::filesystem::path& geometry,
               std::optional<std::size_t> row) {
  Scan scan;
  scan.geometry = Geometry::load(find_geometry(measurement, geometry));
  ArrayFile file = read_array(measurement);
  if (row) {
    scan.measurement = detector_row(file.array, *row);
    scan.non_finite = compute_stats(scan.measurement).non_finite();
  } else {
    scan.measurement = std::move(file.array);
    scan.non_finite = file.non_finite;
  }
  check_scan(scan, measurement.string());
  return scan;
}

std::optional<ScanFiles> read_scan_files(const std::filesystem::path& scan_json) {
  const std::string where = scan_json.string();
  nlohmann::json root;
  try {
    root = nlohmann::json::parse(read_text(scan_json));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(where + ": invalid JSON: " + e.what());
  }
  if (!root.is_object() || !root.contains("files")) return std::nullopt;
  const nlohmann::json& files = root["files"];
  if (!files.is_object()) throw InputError(where + ": files must be an object");
  const std::filesystem::path folder = scan_json.parent_path();
  ScanFiles out;
  for (const auto& [key, value] : files.items()) {
    std::filesystem::path* slot = key == "measurement"   ? &out.measurement
                                  : key == "projections" ? &out.projections
                                  : key == "flat"        ? &out.flat
                                  : key == "dark"        ? &out.dark
                                  : key == "flat_after"  ? &out.flat_after
                                                         : nullptr;
    if (!slot) {
      throw InputError(where + ": files." + key +
                       " is not a scan file (measurement, projections, flat, dark, flat_after)");
    }
    if (!value.is_string() || value.get<std::string>().empty()) {
      throw InputError(where + ": files." + key + " must be a path");
    }
    *slot = folder / value.get<std::string>();
  }
  if (out.measurement.empty() == out.projections.empty()) {
    throw InputError(where + ": files needs either measurement (rho) or projections (raw)");
  }
  if (!out.measurement.empty() && !(out.flat.empty() && out.dark.empty())) {
    throw InputError(where +
                     ": files.flat and files.dark go with projections (raw), not measurement");
  }
  if (out.flat.empty() && !out.dark.empty()) {
    throw InputError(where + ": files.dark needs files.flat");
  }
  if (out.flat.empty() && !out.flat_after.empty()) {
    throw InputError(where + ": files.flat_after needs files.flat");
  }
  return out;
}

}  // namespace riner
