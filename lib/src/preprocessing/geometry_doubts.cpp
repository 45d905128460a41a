#include "riner/geometry_doubts.hpp"

#include <optional>

#include "preprocessing/centre_readings.hpp"
#include "preprocessing/fan_doubts.hpp"
#include "riner/angular_range.hpp"
#include "riner/error.hpp"

namespace riner {

std::optional<std::string> fan_geometry_doubt(const Scan& scan) {
  const Geometry& g = scan.geometry;
  if (!g.is_divergent() || !preprocessing::holds_structure(scan.measurement)) return std::nullopt;
  if (g.type == GeometryType::kCone3d && !preprocessing::source_plane_on_detector(g)) {
    return std::nullopt;
  }
  const Scan fan = preprocessing::compared_fan(scan);
  if (std::optional<std::string> doubt = preprocessing::reversed_fan_doubt(fan, g.offset_u)) {
    return doubt;
  }
  return preprocessing::distance_fan_doubt(fan, g.offset_u);
}

std::vector<std::string> geometry_doubts(const Scan& scan) {
  std::vector<std::string> out;
  // A check that only warns never stops a run: readings it cannot read say nothing.
  try {
    for (std::optional<std::string> doubt : {angular_range_doubt(scan), fan_geometry_doubt(scan)}) {
      if (doubt) out.push_back(std::move(*doubt));
    }
  } catch (const InputError&) {
    return {};
  }
  return out;
}

}  // namespace riner
