// The ring corrections' settings, each described once (settings/setting.hpp): the config
// reads, writes and validates them through these tables, and each correction validates the
// settings it is handed with the same bounds.
#pragma once

#include <vector>

#include "riner/ring_correction.hpp"
#include "settings/setting.hpp"

namespace riner::rings {

const std::vector<settings::Setting<AirRingSettings>>& air_settings();
const std::vector<settings::Setting<GradientRingSettings>>& gradient_settings();
const std::vector<settings::Setting<ResponseRingSettings>>& response_settings();
const std::vector<settings::Setting<MirrorRingSettings>>& mirror_settings();

// InputError "`what`: rings.KEY must be ..." for the first setting outside its range.
void validate(const char* what, const AirRingSettings& s);
void validate(const char* what, const GradientRingSettings& s);
void validate(const char* what, const ResponseRingSettings& s);
void validate(const char* what, const MirrorRingSettings& s);

}  // namespace riner::rings
