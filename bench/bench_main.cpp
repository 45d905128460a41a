// riner_bench: run benchmark cases, print a table, append JSON lines.
//   riner_bench --case=NAME|all [--size=tiny|small|medium|large] [--runs=N] [--warmup=N]
//               [--device=SEL] [--json=FILE] [--KEY=VALUE ...]
#include <cstdio>
#include <cstring>
#include <fstream>
#include <string>

#include "harness.hpp"
#include "riner/device.hpp"
#include "riner/error.hpp"

int main(int argc, char** argv) {
  riner::bench::Options options;
  options.self = argv[0];
  std::string which = "all";
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::printf(
          "usage: riner_bench --case=NAME|all [--size=S] [--runs=N] [--warmup=N] "
          "[--device=SEL] [--json=FILE]\n\ncases:\n");
      for (const auto& c : riner::bench::cases()) {
        std::printf("  %-20s %s\n", c.name.c_str(), c.summary.c_str());
      }
      return 0;
    }
    if (arg.rfind("--", 0) != 0 || arg.find('=') == std::string::npos) {
      std::fprintf(stderr, "riner_bench: expected --key=value, got '%s'\n", arg.c_str());
      return 2;
    }
    const std::string key = arg.substr(2, arg.find('=') - 2);
    const std::string value = arg.substr(arg.find('=') + 1);
    if (key == "case")
      which = value;
    else if (key == "size")
      options.size = value;
    else if (key == "runs")
      options.runs = std::stoi(value);
    else if (key == "warmup")
      options.warmup = std::stoi(value);
    else if (key == "device")
      options.device = value;
    else if (key == "json")
      options.json_path = value;
    else
      options.extra[key] = value;
  }
  bool ran = false;
  for (const auto& c : riner::bench::cases()) {
    if (which != "all" && which != c.name) continue;
    ran = true;
    try {
      for (const riner::bench::Result& r : c.fn(options)) {
        if (r.line.empty())
          std::printf("%-20s %s\n", r.case_name.c_str(), r.fields.dump().c_str());
        else
          std::printf("%s\n", r.line.c_str());
        std::fflush(stdout);
        if (!options.json_path.empty()) {
          nlohmann::json line = r.fields;
          line["case"] = r.case_name;
          line["size"] = options.size;
          line["meta"] =
              riner::bench::metadata(riner::Device::open(options.device).info(), options);
          std::ofstream(options.json_path, std::ios::app) << line.dump() << "\n";
        }
      }
    } catch (const riner::BuildError& e) {
      std::fprintf(stderr, "riner_bench: case %s failed: %s\n%s\n", c.name.c_str(), e.what(),
                   e.log().c_str());
      return 1;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "riner_bench: case %s failed: %s\n", c.name.c_str(), e.what());
      return 1;
    }
  }
  if (!ran) {
    std::fprintf(stderr, "riner_bench: no case named '%s' (see --help)\n", which.c_str());
    return 2;
  }
  // Checked after the run (cases read their options as they go): the results stand, the exit
  // status says that an option did nothing.
  int ignored = 0;
  for (const auto& [key, value] : options.extra) {
    if (options.read.count(key) != 0) continue;
    std::fprintf(stderr, "riner_bench: --%s=%s was not read by case %s (a typo?)\n", key.c_str(),
                 value.c_str(), which.c_str());
    ++ignored;
  }
  return ignored > 0 ? 2 : 0;
}
