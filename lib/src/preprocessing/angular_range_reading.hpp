// read_angular_range (riner/angular_range.hpp) on readings already prepared as the centre
// finders prepare them (preprocessing/centre_readings.hpp), which estimate_centre has at hand.
#pragma once

#include "riner/angular_range.hpp"

namespace riner::preprocessing {

AngularRangeEvidence read_prepared_angular_range(const Scan& prepared);

}  // namespace riner::preprocessing
