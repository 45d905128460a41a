// riner settings: every setting a config file (or --set) can change, with its default, allowed
// values and meaning, from the library's one settings table.
#include <cstdio>

#include "cli_common.hpp"
#include "commands.hpp"
#include "riner/riner_config.hpp"

namespace riner::app {

int run_settings(int argc, char** argv, int first) {
  Args args("settings",
            "Lists every setting of `riner reconstruct` (--config FILE, --set NAME=VALUE): its "
            "default, the values it takes and what it does. With --paper, the paper preset's "
            "values as defaults.");
  args.flag("markdown", "print a Markdown table (the README's)");
  args.output_flags();
  if (!args.parse(argc, argv, first)) return 0;
  Console console(args);
  const std::vector<RinerConfig::SettingInfo> settings = RinerConfig::settings();
  nlohmann::json list = nlohmann::json::array();
  for (const auto& s : settings) {
    list.push_back({{"name", s.name},
                    {"type", s.type},
                    {"allowed", s.allowed},
                    {"default", nlohmann::json::parse(s.default_value)},
                    {"help", s.help}});
  }
  if (args.is_set("markdown")) {
    std::printf("| setting | default | allowed | what it does |\n|---|---|---|---|\n");
    for (const auto& s : settings) {
      std::printf("| `%s` | `%s` | %s | %s |\n", s.name.c_str(), s.default_value.c_str(),
                  s.allowed.c_str(), s.help.c_str());
    }
  } else {
    for (const auto& s : settings) {
      console.line(s.name + " = " + s.default_value + "  (" + s.allowed + ")\n    " + s.help);
    }
  }
  console.summary({{"settings", list}});
  return 0;
}

}  // namespace riner::app
