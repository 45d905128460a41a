// JSON a user wrote (a geometry, settings, a scan's files, a raw sidecar), parsed strictly: a key
// given twice in one object is refused, where a parser silently keeps the last ("steps": 100
// then "steps": 5 trained 5 steps; "detector" twice kept the second).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

namespace riner::util {

// InputError "SOURCE: invalid JSON: ..." or "SOURCE: the key "K" appears twice in one object".
nlohmann::json parse_user_json(std::string_view text, const std::string& source);

}  // namespace riner::util
