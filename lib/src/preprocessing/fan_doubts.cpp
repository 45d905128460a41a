#include "preprocessing/fan_doubts.hpp"

#include <cmath>
#include <cstdio>

#include "preprocessing/centre_conjugate.hpp"

namespace riner::preprocessing {

std::optional<std::string> reversed_fan_doubt(const Scan& fan, double offset_px) {
  const std::optional<FanSense> sense = conjugate_sense(fan, offset_px);
  if (!sense || sense->cost_reversed * kFanDoubtContrast > sense->cost_as_given) {
    return std::nullopt;
  }
  char line[400];
  std::snprintf(line, sizeof(line),
                "the fan's rays meet their conjugates with the views turning the other way (the "
                "angles negated, or the detector's columns reversed): mismatch %.2f%% of the "
                "readings' spread, %.2f%% as given; check the rotation direction and the "
                "detector's orientation",
                100.0 * sense->cost_reversed, 100.0 * sense->cost_as_given);
  return std::string(line);
}

std::optional<std::string> distance_fan_doubt(const Scan& fan, double offset_px) {
  const Geometry& g = fan.geometry;
  const std::optional<FanDistanceFit> fit = conjugate_fan_distance(fan, offset_px);
  if (!fit || std::fabs(std::log(fit->scale)) < std::log(kDistanceDoubtFactor) ||
      fit->cost * kFanDoubtContrast > fit->cost_as_given) {
    return std::nullopt;
  }
  const double sdd = g.source_origin_mm + g.origin_detector_mm;
  char line[600];
  std::snprintf(
      line, sizeof(line),
      "the fan's rays meet their conjugates where the source sits %.0f mm from the detector, "
      "%.2f times the geometry's %.0f mm (source_origin_mm %g + origin_detector_mm %g), or "
      "with a detector pitch %.2f times the given %g mm: mismatch %.2f%% of the readings' "
      "spread, %.2f%% as given; check the distances (origin_detector_mm runs from the axis, "
      "not the source) and the pitch (after binning)",
      fit->scale * sdd, fit->scale, sdd, g.source_origin_mm, g.origin_detector_mm, 1.0 / fit->scale,
      g.pitch_u, 100.0 * fit->cost, 100.0 * fit->cost_as_given);
  return std::string(line);
}

}  // namespace riner::preprocessing
