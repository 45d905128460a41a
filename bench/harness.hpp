// The benchmark harness: case registry, timing statistics, machine-readable results.
#pragma once

#include <chrono>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace riner::bench {

struct Options {
  std::string size = "small";  // tiny | small | medium | large
  int runs = 10;
  int warmup = 2;
  std::string device;
  std::string json_path;                     // JSON lines appended here when set
  std::string self;                          // argv[0], for cases that time fresh processes
  std::map<std::string, std::string> extra;  // --key=value options a case understands
};

struct Stats {
  double min = 0, median = 0, mean = 0, stddev = 0, max = 0;
  static Stats of(std::vector<double> samples);
};

// One result row: printed as a table line and written as one JSON object.
struct Result {
  std::string case_name;
  nlohmann::json fields;  // everything measured, in the case's own units
};

using CaseFn = std::function<std::vector<Result>(const Options&)>;

void register_case(const std::string& name, const std::string& summary, CaseFn fn);

struct CaseEntry {
  std::string name;
  std::string summary;
  CaseFn fn;
};
const std::vector<CaseEntry>& cases();

// Wall-clock milliseconds of fn().
double time_ms(const std::function<void()>& fn);

// Metadata stamped on every JSON line: date, git revision, host, device.
nlohmann::json metadata(const std::string& device_name);

}  // namespace riner::bench

#define RINER_BENCH_CASE(name, summary, fn)              \
  static const bool riner_bench_registered_##name = [] { \
    ::riner::bench::register_case(#name, summary, fn);   \
    return true;                                         \
  }()
