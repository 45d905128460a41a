// What a scan's readings say against its geometry, one line each: views that turn twice or half
// as far as the angles say (riner/angular_range.hpp), a fan whose distances or rotation sense
// pair rays with the wrong conjugates (fan_geometry_doubt, below). Each makes the
// reconstruction garbage without any other sign; the commands warn with these lines and
// summary.json keeps them (geometry_doubts).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "riner/scan.hpp"

namespace riner {

// Empty where nothing is doubted, or where the readings cannot be read (all NaN, say: the run
// says so in its own words).
std::vector<std::string> geometry_doubts(const Scan& scan);

// A fan or cone beam (its fan through the source's plane) over a full turn: one line where the
// readings pair rays with their conjugates several times better (4x) with the views turning
// the other way (the angles negated, or the detector's columns reversed), or under a
// source-detector distance at least 10% from the geometry's (a distance or a pitch given
// wrong: TIGRE's DSD as origin_detector_mm, a pitch before binning), searched from half to
// twice it; about the geometry's offset within 2 px (the sense also about its mirror image:
// preprocessing/centre_conjugate.hpp). nullopt where they agree, for a parallel beam, where no
// full turn is read, or where a cone's source plane projects off its detector.
std::optional<std::string> fan_geometry_doubt(const Scan& scan);

}  // namespace riner
