// The benchmark harness: case registry, timing statistics, machine-readable results.
#pragma once

#include <chrono>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "riner/device.hpp"

namespace riner::bench {

struct Options {
  std::string size = "small";  // tiny | small | medium | large
  int runs = 10;
  int warmup = 2;
  std::string device;
  std::string json_path;                     // JSON lines appended here when set
  std::string self;                          // argv[0], for cases that time fresh processes
  std::map<std::string, std::string> extra;  // --key=value options a case understands
  // The keys of `extra` a case asked for: any other was ignored (a typo reads as the defaults).
  mutable std::set<std::string> read;

  // A case's own option (--key=value), or the fallback.
  std::string get(const std::string& key, const std::string& fallback) const;
  int get_int(const std::string& key, int fallback) const;
  double get_double(const std::string& key, double fallback) const;
  // The folder --key names, created up front so that an hour-long case does not fail at
  // its last write; empty when the option is absent and fallback is empty.
  std::string output_dir(const std::string& key, const std::string& fallback) const;
};

struct Stats {
  double min = 0, median = 0, mean = 0, stddev = 0, max = 0;
  double q25 = 0, q75 = 0;  // quartiles (linear interpolation)
  static Stats of(std::vector<double> samples);
  nlohmann::json to_json() const;
};

// One result row: printed as a table line and written as one JSON object.
struct Result {
  Result(std::string case_name_, nlohmann::json fields_, std::string line_ = "")
      : case_name(std::move(case_name_)), fields(std::move(fields_)), line(std::move(line_)) {}
  std::string case_name;
  nlohmann::json fields;  // everything measured, in the case's own units
  std::string line;       // a table row for stdout; the fields are printed when empty
};

// printf into a std::string (for table rows).
std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));

// "1.5,3.2,3.2" -> {1.5, 3.2, 3.2}; empty items are skipped (an option's list of numbers).
std::vector<double> number_list(const std::string& text);
// "160,640" -> {160, 640}, the same for whole numbers.
std::vector<int> int_list(const std::string& text);

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

// Metadata stamped on every JSON line: date, git revision, host, device and driver, and the
// harness settings of the run.
nlohmann::json metadata(const DeviceInfo& device, const Options& options);

}  // namespace riner::bench

#define RINER_BENCH_CASE(name, summary, fn)              \
  static const bool riner_bench_registered_##name = [] { \
    ::riner::bench::register_case(#name, summary, fn);   \
    return true;                                         \
  }()
