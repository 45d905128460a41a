#include "cli_args.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

namespace riner::app {

Args::Args(std::string command, std::string summary)
    : command_(std::move(command)), summary_(std::move(summary)) {}

Args& Args::positional(const std::string& name, const std::string& help, bool required) {
  positionals_.push_back({name, "", help, std::nullopt, required});
  return *this;
}

Args& Args::option(const std::string& name, const std::string& value_name, const std::string& help,
                   std::optional<std::string> default_value) {
  options_.push_back({name, value_name, help, std::move(default_value), false});
  return *this;
}

Args& Args::list_option(const std::string& name, const std::string& value_name,
                         const std::string& help) {
  option(name, value_name, help, "");
  options_.back().joins = true;
  return *this;
}

Args& Args::flag(const std::string& name, const std::string& help) {
  options_.push_back({name, "", help, std::nullopt, false});
  return *this;
}

Args& Args::output_flags() {
  flag("quiet", "print nothing but errors");
  flag("json", "print a JSON summary on stdout");
  return *this;
}

const Args::Spec* Args::find_option(const std::string& name) const {
  for (const Spec& spec : options_) {
    if (spec.name == name) return &spec;
  }
  return nullptr;
}

bool Args::parse(int argc, char** argv, int first) {
  std::size_t next_positional = 0;
  bool options_done = false;
  for (int i = first; i < argc; ++i) {
    std::string arg = argv[i];
    if (!options_done && (arg == "--help" || arg == "-h")) {
      std::fputs(help().c_str(), stdout);
      return false;
    }
    if (!options_done && arg == "--") {
      options_done = true;
      continue;
    }
    if (!options_done && arg.size() > 2 && arg.compare(0, 2, "--") == 0) {
      std::string name = arg.substr(2);
      std::optional<std::string> value;
      if (auto eq = name.find('='); eq != std::string::npos) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
      }
      const Spec* spec = find_option(name);
      if (spec == nullptr) throw UsageError("unknown option --" + name);
      if (spec->value_name.empty()) {
        if (value) throw UsageError("--" + name + " takes no value");
        flags_[name] = true;
        continue;
      }
      if (!value) {
        if (i + 1 >= argc)
          throw UsageError("--" + name + " needs a value (" + spec->value_name + ")");
        value = argv[++i];
      }
      if (auto it = values_.find(name); spec->joins && it != values_.end()) {
        if (!value->empty()) it->second += it->second.empty() ? *value : "," + *value;
      } else {
        values_[name] = *value;
      }
      continue;
    }
    if (next_positional >= positionals_.size()) {
      // The shell expanded an unquoted pattern into its files: the second is "unexpected".
      const bool expanded =
          !positionals_.empty() && std::filesystem::exists(arg) &&
          std::filesystem::path(arg).extension() ==
              std::filesystem::path(values_[positionals_.back().name]).extension();
      throw UsageError("unexpected argument '" + arg + "'" +
                       (expanded ? " (the shell expanded a pattern into its files: quote it, "
                                   "'proj_*.tif')"
                                 : ""));
    }
    values_[positionals_[next_positional++].name] = arg;
  }
  for (std::size_t p = next_positional; p < positionals_.size(); ++p) {
    if (positionals_[p].required) throw UsageError("missing " + positionals_[p].name);
  }
  return true;
}

bool Args::has(const std::string& name) const {
  if (values_.count(name)) return true;
  const Spec* spec = find_option(name);
  return spec != nullptr && spec->default_value.has_value();
}

bool Args::given(const std::string& name) const { return values_.count(name) > 0; }

std::optional<std::string> Args::maybe(const std::string& name) const {
  if (auto it = values_.find(name); it != values_.end()) return it->second;
  if (const Spec* spec = find_option(name); spec != nullptr) return spec->default_value;
  return std::nullopt;
}

std::string Args::get(const std::string& name) const {
  auto value = maybe(name);
  if (!value) throw UsageError("missing --" + name);
  return *value;
}

double Args::number(const std::string& name) const {
  const std::string text = get(name);
  char* end = nullptr;
  errno = 0;
  const double v = std::strtod(text.c_str(), &end);
  if (end == text.c_str() || *end != '\0' || errno != 0 || !std::isfinite(v)) {
    throw UsageError("--" + name + " expects a number, got '" + text + "'");
  }
  return v;
}

long Args::integer(const std::string& name) const {
  const std::string text = get(name);
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (end == text.c_str() || *end != '\0' || errno != 0) {
    throw UsageError("--" + name + " expects an integer, got '" + text + "'");
  }
  return v;
}

bool Args::is_set(const std::string& flag) const { return flags_.count(flag) > 0; }

std::string Args::help() const {
  std::string text = "usage: riner " + command_;
  for (const Spec& p : positionals_) text += p.required ? " " + p.name : " [" + p.name + "]";
  if (!options_.empty()) text += " [options]";
  text += "\n\n" + summary_ + "\n";
  if (!positionals_.empty()) {
    text += "\narguments:\n";
    for (const Spec& p : positionals_) text += "  " + p.name + "\n      " + p.help + "\n";
  }
  if (!options_.empty()) {
    text += "\noptions:\n";
    for (const Spec& o : options_) {
      text +=
          "  --" + o.name + (o.value_name.empty() ? "" : " " + o.value_name) + "\n      " + o.help;
      // A help that says its default in words (compare's --data-range) keeps its own.
      if (o.default_value && !o.default_value->empty() &&
          o.help.find("(default:") == std::string::npos)
        text += " (default: " + *o.default_value + ")";
      text += "\n";
    }
  }
  text += "  --help\n      show this help\n";
  return text;
}

}  // namespace riner::app
