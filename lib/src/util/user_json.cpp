#include "util/user_json.hpp"

#include <set>
#include <vector>

#include "riner/error.hpp"

namespace riner::util {

namespace {

struct DuplicateKey {
  std::string key;
};

}  // namespace

nlohmann::json parse_user_json(std::string_view text, const std::string& source) {
  std::vector<std::set<std::string>> objects;  // the keys seen in each open object
  const nlohmann::json::parser_callback_t watch =
      [&](int, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
        switch (event) {
          case nlohmann::json::parse_event_t::object_start: objects.emplace_back(); break;
          case nlohmann::json::parse_event_t::object_end:
            if (!objects.empty()) objects.pop_back();
            break;
          case nlohmann::json::parse_event_t::key:
            if (!objects.empty() && !objects.back().insert(parsed.get<std::string>()).second) {
              throw DuplicateKey{parsed.get<std::string>()};
            }
            break;
          default: break;
        }
        return true;
      };
  try {
    return nlohmann::json::parse(text, watch);
  } catch (const DuplicateKey& d) {
    throw InputError(source + ": the key \"" + d.key +
                     "\" appears twice in one object (which one is meant?)");
  } catch (const nlohmann::json::exception& e) {
    // Python's json.dump writes NaN and Infinity, which JSON has no word for.
    const std::string what = e.what();
    const bool non_number =
        what.find("last read: '") != std::string::npos &&
        (what.find("N'") != std::string::npos || what.find("I'") != std::string::npos ||
         what.find("-I'") != std::string::npos);
    throw InputError(source + ": invalid JSON: " + what +
                     (non_number ? " (NaN and Infinity are no JSON numbers: every value must be a "
                                   "finite number)"
                                 : ""));
  }
}

}  // namespace riner::util
