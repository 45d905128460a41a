#include "riner/geometry_doubts.hpp"

#include <optional>

#include "riner/angular_range.hpp"
#include "riner/centre.hpp"

namespace riner {

std::vector<std::string> geometry_doubts(const Scan& scan) {
  std::vector<std::string> out;
  for (std::optional<std::string> doubt : {angular_range_doubt(scan), fan_distance_doubt(scan)}) {
    if (doubt) out.push_back(std::move(*doubt));
  }
  return out;
}

}  // namespace riner
