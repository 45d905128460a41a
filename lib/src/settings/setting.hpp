// One setting of a settings struct, described once: its JSON name, type, allowed range and a
// line of help. Tables of these drive reading, writing and validating a struct, and the
// settings list users read (`riner settings`), so adding a setting is one line in a table.
#pragma once

#include <cmath>
#include <functional>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <type_traits>
#include <vector>

namespace riner::settings {

enum class Type { kBool, kInteger, kNumber, kChoice };

// An interval; an open end excludes its bound. Integers print as lo..hi.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;
  bool hi_open = false;

  bool contains(double v) const {
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
};

inline Range closed(double lo, double hi) { return {lo, hi, false, false}; }
inline Range open(double lo, double hi) { return {lo, hi, true, true}; }
inline Range open_closed(double lo, double hi) { return {lo, hi, true, false}; }
inline Range closed_open(double lo, double hi) { return {lo, hi, false, true}; }

template <typename Owner>
struct Setting {
  std::string section;  // the JSON object it lives in ("training"); empty at the top level
  std::string key;
  Type type = Type::kNumber;
  Range range;                       // kInteger and kNumber
  std::vector<std::string> choices;  // kChoice
  std::string help;
  std::function<nlohmann::json(const Owner&)> get;
  std::function<void(Owner&, const nlohmann::json&)> set;  // a value of the right type

  std::string name() const { return section.empty() ? key : section + "." + key; }
};

// The member an access path (&A::b, &B::c, ...) leads to from `owner`.
template <typename Owner, typename... Members>
decltype(auto) member_at(Owner& owner, Members... path) {
  return (owner.*....*path);
}

// A setting's description, without its accessors.
template <typename Owner>
Setting<Owner> described(std::string section, std::string key, Type type, std::string help) {
  Setting<Owner> s;
  s.section = std::move(section);
  s.key = std::move(key);
  s.type = type;
  s.help = std::move(help);
  return s;
}

// A bool, integer or floating-point member reached by `path` from Owner.
template <typename Owner, typename... Members>
Setting<Owner> field(std::string section, std::string key, Range range, std::string help,
                     Members... path) {
  using T = std::remove_reference_t<decltype(member_at(std::declval<Owner&>(), path...))>;
  Setting<Owner> s = described<Owner>(std::move(section), std::move(key),
                                      std::is_same_v<T, bool> ? Type::kBool
                                      : std::is_integral_v<T> ? Type::kInteger
                                                              : Type::kNumber,
                                      std::move(help));
  s.range = range;
  s.get = [=](const Owner& o) { return nlohmann::json(member_at(o, path...)); };
  s.set = [=](Owner& o, const nlohmann::json& v) { member_at(o, path...) = v.get<T>(); };
  return s;
}

// A member with named values: a std::string, or an enum with `name_of(value)` for each of
// `values`.
template <typename Owner, typename... Members>
Setting<Owner> string_choice(std::string section, std::string key, std::vector<std::string> choices,
                             std::string help, Members... path) {
  Setting<Owner> s =
      described<Owner>(std::move(section), std::move(key), Type::kChoice, std::move(help));
  s.choices = std::move(choices);
  s.get = [=](const Owner& o) { return nlohmann::json(member_at(o, path...)); };
  s.set = [=](Owner& o, const nlohmann::json& v) { member_at(o, path...) = v.get<std::string>(); };
  return s;
}

template <typename Owner, typename Enum, typename... Members>
Setting<Owner> enum_choice(std::string section, std::string key, std::vector<Enum> values,
                           const char* (*name_of)(Enum), std::string help, Members... path) {
  Setting<Owner> s =
      described<Owner>(std::move(section), std::move(key), Type::kChoice, std::move(help));
  for (Enum e : values) s.choices.emplace_back(name_of(e));
  s.get = [=](const Owner& o) { return nlohmann::json(name_of(member_at(o, path...))); };
  s.set = [=](Owner& o, const nlohmann::json& v) {
    const std::string name = v.get<std::string>();
    for (Enum e : values) {
      if (name == name_of(e)) member_at(o, path...) = e;
    }
  };
  return s;
}

// The same setting seen from an Outer struct that holds Owner at `path`.
template <typename Outer, typename Owner, typename... Members>
Setting<Outer> lift(const Setting<Owner>& inner, Members... path) {
  Setting<Outer> s = described<Outer>(inner.section, inner.key, inner.type, inner.help);
  s.range = inner.range;
  s.choices = inner.choices;
  s.get = [get = inner.get, path...](const Outer& o) { return get(member_at(o, path...)); };
  s.set = [set = inner.set, path...](Outer& o, const nlohmann::json& v) {
    set(member_at(o, path...), v);
  };
  return s;
}

// "in 0..64" / "in (0, 1]".
std::string describe_range(Type type, const Range& range);

// "a, b, c".
std::string join_choices(const std::vector<std::string>& choices);

// The JSON value's type against the setting's: an empty string when it fits, else why not.
std::string type_mismatch(Type type, const std::vector<std::string>& choices,
                          const nlohmann::json& value);

template <typename Owner>
std::string allowed(const Setting<Owner>& s) {
  if (s.type == Type::kBool) return "true or false";
  if (s.type == Type::kChoice) return "one of " + join_choices(s.choices);
  return describe_range(s.type, s.range);
}

// Why a number `v` does not fit setting s ("section.key must be in ... (help)"); empty when it
// does.
template <typename Owner>
std::string out_of_range(const Setting<Owner>& s, double v) {
  if (s.range.contains(v)) return {};
  return s.name() + " must be " + allowed(s) + " (" + s.help + ")";
}

// The first setting of `table` whose value in `owner` is outside its range, as
// "section.key must be in ... (help)"; empty when all are inside.
template <typename Owner>
std::string first_violation(const Owner& owner, const std::vector<Setting<Owner>>& table) {
  for (const Setting<Owner>& s : table) {
    if (s.type != Type::kInteger && s.type != Type::kNumber) continue;
    std::string problem = out_of_range(s, s.get(owner).template get<double>());
    if (!problem.empty()) return problem;
  }
  return {};
}

}  // namespace riner::settings
