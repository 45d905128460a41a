#include "riner/scan.hpp"

#include "io/file_access.hpp"

#include "riner/error.hpp"
#include "riner/io.hpp"

namespace riner {

void check_scan(const Scan& scan, std::string_view what) {
  scan.geometry.check_measurement_shape(scan.measurement.shape, what);
  if (scan.measurement.size() > 0 && scan.non_finite >= scan.measurement.size()) {
    throw InputError(std::string(what) + ": all " + std::to_string(scan.measurement.size()) +
                     " values are NaN or infinite; there is nothing to reconstruct");
  }
}

Scan load_scan(const std::filesystem::path& measurement, const std::filesystem::path& geometry) {
  io::input_file_size(measurement);  // a missing scan is the first thing to report
  std::filesystem::path geometry_path = geometry;
  if (geometry_path.empty()) {
    geometry_path = measurement.parent_path() / "geometry.json";
    if (!std::filesystem::exists(geometry_path)) {
      throw InputError(measurement.string() +
                       ": no geometry given and no geometry.json beside it (use --geometry)");
    }
  }
  Scan scan;
  scan.geometry = Geometry::load(geometry_path);
  ArrayFile file = read_array(measurement);
  scan.measurement = std::move(file.array);
  scan.non_finite = file.non_finite;
  check_scan(scan, measurement.string());
  return scan;
}

}  // namespace riner
