#include "settings/setting.hpp"

#include <cmath>
#include <cstdio>

namespace riner::settings {

namespace {

std::string bound(Type type, double v) {
  char text[40];
  if (type == Type::kInteger && std::fabs(v) < 1e15) {
    std::snprintf(text, sizeof(text), "%.0f", v);
  } else {
    std::snprintf(text, sizeof(text), "%g", v);
  }
  return text;
}

}  // namespace

std::string describe_range(Type type, const Range& range) {
  if (type == Type::kInteger) {
    // Integer ranges are closed by construction.
    return "in " + bound(type, range.lo) + ".." + bound(type, range.hi);
  }
  return std::string("in ") + (range.lo_open ? "(" : "[") + bound(type, range.lo) + ", " +
         bound(type, range.hi) + (range.hi_open ? ")" : "]");
}

std::string join_choices(const std::vector<std::string>& choices) {
  std::string list;
  for (std::size_t i = 0; i < choices.size(); ++i) list += (i ? ", " : "") + choices[i];
  return list;
}

std::string type_mismatch(Type type, const std::vector<std::string>& choices,
                          const nlohmann::json& value) {
  switch (type) {
    case Type::kBool:
      return value.is_boolean() ? "" : "must be true or false";
    case Type::kInteger:
      if (value.is_number_integer()) return "";
      // JSON holds an integer past 64 bits (Python's 2**70) as a float: say which it was.
      if (value.is_number_float()) {
        const double v = value.get<double>();
        const bool beyond =
            std::floor(v) == v && (v >= std::ldexp(1.0, 64) || v < -std::ldexp(1.0, 63));
        return std::string("must be an integer (got ") + value.dump() +
               (beyond ? ", beyond 64 bits)" : ")");
      }
      return "must be an integer";
    case Type::kNumber:
      return value.is_number() ? "" : "must be a number (got " + value.dump() + ")";
    case Type::kChoice: {
      if (!value.is_string()) return "must be a string: one of " + join_choices(choices);
      for (const std::string& c : choices) {
        if (value.get<std::string>() == c) return "";
      }
      return "must be one of " + join_choices(choices);
    }
  }
  return "has an unknown type";
}

}  // namespace riner::settings
