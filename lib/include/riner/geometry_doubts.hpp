// What a scan's readings say against its geometry, one line each: views that turn twice or half
// as far as the angles say (riner/angular_range.hpp), a fan whose distances pair rays with the
// wrong conjugates (riner/centre.hpp's fan_distance_doubt). A wrong range or distance makes the
// reconstruction garbage without any other sign; the commands warn with these lines and
// summary.json keeps them (geometry_doubts).
#pragma once

#include <string>
#include <vector>

#include "riner/scan.hpp"

namespace riner {

// Empty where nothing is doubted.
std::vector<std::string> geometry_doubts(const Scan& scan);

}  // namespace riner
