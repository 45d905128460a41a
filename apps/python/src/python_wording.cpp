#include "python_wording.hpp"

#include <array>
#include <cctype>
#include <string_view>
#include <utility>

namespace riner::python {
namespace {

// Phrases first (an offset in pixels becomes the axis's column), then single options; an
// option matches only whole (--flat is not the start of --flat-after).
constexpr std::array<std::pair<std::string_view, std::string_view>, 14> kWording{{
    {"(--fill-stopped-beam interpolates them)", "(fill_stopped_beam=True interpolates them)"},
    {"--json: stopped_beam_readings", "return_report=True: stopped_beam_readings"},
    {"riner reconstruct trains", "riner.reconstruct trains"},
    {"pass the offset with --offset-px", "pass the axis's column with center="},
    {"pass --offset-px auto", "pass center=\"auto\""},
    {"--mu-unit cm", "mu_unit=\"cm\""},
    {"see `riner devices`", "see riner.devices()"},
    {"--offset-px", "center="},
    {"--flat-after", "flat_after="},
    {"--flat", "flat="},
    {"--dark", "dark="},
    {"--geometry", "geometry="},
    {"--row", "row="},
    {"--device", "device"},
}};

bool continues_option(const std::string& s, std::size_t at) {
  if (at >= s.size()) return false;
  const auto c = static_cast<unsigned char>(s[at]);
  return std::islower(c) != 0 || std::isdigit(c) != 0 || c == '-' || c == '_';
}

}  // namespace

std::string python_wording(std::string message) {
  for (const auto& [cli, python] : kWording) {
    for (std::size_t at = message.find(cli); at != std::string::npos; at = message.find(cli, at)) {
      if (continues_option(message, at + cli.size())) {
        at += cli.size();
        continue;
      }
      message.replace(at, cli.size(), python);
      at += python.size();
    }
  }
  return message;
}

}  // namespace riner::python
