// What a fan's conjugate rays say against its geometry (preprocessing/centre_conjugate.hpp):
// views that turned the other way, a source-detector distance given wrong. Each reads `fan`
// as compared_fan (preprocessing/centre_readings.hpp) prepares it, about `offset_px`.
#pragma once

#include <optional>
#include <string>

#include "riner/scan.hpp"

namespace riner::preprocessing {

// One line where the angles negated (or the columns reversed) pair rays with their conjugates
// kFanDoubtContrast times better than as given.
std::optional<std::string> reversed_fan_doubt(const Scan& fan, double offset_px);

// One line where a source-detector distance at least kDistanceDoubtFactor from the geometry's
// does so.
std::optional<std::string> distance_fan_doubt(const Scan& fan, double offset_px);

// The contrast either must reach, and the least factor on the distance that counts.
constexpr double kFanDoubtContrast = 4.0;
constexpr double kDistanceDoubtFactor = 1.1;

}  // namespace riner::preprocessing
