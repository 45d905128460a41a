// Command-line parsing shared by every subcommand: positional arguments, --name VALUE (or
// --name=VALUE) options and flags, generated --help, and UsageError for anything unknown.
#pragma once

#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace riner::app {

// Bad usage: exit code 2, message plus a pointer to --help.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class Args {
 public:
  Args(std::string command, std::string summary);

  Args& positional(const std::string& name, const std::string& help, bool required = true);
  Args& option(const std::string& name, const std::string& value_name, const std::string& help,
               std::optional<std::string> default_value = std::nullopt);
  Args& flag(const std::string& name, const std::string& help);
  // An option whose value is a comma-separated list: given more than once, the lists join in
  // order (--set a=1 --set b=2 is --set a=1,b=2), where another option's last value wins.
  Args& list_option(const std::string& name, const std::string& value_name,
                    const std::string& help);
  // --quiet, --json: every subcommand has them.
  Args& output_flags();

  // Parses argv[first..argc); returns false when --help was printed.
  bool parse(int argc, char** argv, int first);

  bool has(const std::string& name) const;
  bool given(const std::string& name) const;       // on the command line, not by a default
  std::string get(const std::string& name) const;  // UsageError if absent without default
  std::optional<std::string> maybe(const std::string& name) const;
  double number(const std::string& name) const;
  long integer(const std::string& name) const;
  bool is_set(const std::string& flag) const;

  std::string help() const;

 private:
  struct Spec {
    std::string name;
    std::string value_name;  // empty for flags
    std::string help;
    std::optional<std::string> default_value;
    bool required = false;
    bool joins = false;  // list_option
  };
  const Spec* find_option(const std::string& name) const;

  std::string command_;
  std::string summary_;
  std::vector<Spec> positionals_;
  std::vector<Spec> options_;
  std::map<std::string, std::string> values_;
  std::map<std::string, bool> flags_;
};

}  // namespace riner::app
