// Every setting of RinerConfig in one table (settings/setting.hpp): its JSON section and key,
// type, range and help. RinerConfig reads, writes and validates through it, `riner settings`
// prints it, and adding a setting is one line here.
#pragma once

#include <vector>

#include "riner/riner_config.hpp"
#include "settings/setting.hpp"

namespace riner {

const std::vector<settings::Setting<RinerConfig>>& config_settings();

// The JSON sections, in the order the table lists them ("" for top-level keys).
std::vector<std::string> config_sections();

}  // namespace riner
