#include "harness.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <numeric>
#include <sstream>

#include "riner/cores.hpp"

namespace riner::bench {

Stats Stats::of(std::vector<double> s) {
  Stats st;
  if (s.empty()) return st;
  std::sort(s.begin(), s.end());
  st.min = s.front();
  st.max = s.back();
  st.median = s.size() % 2 ? s[s.size() / 2] : 0.5 * (s[s.size() / 2 - 1] + s[s.size() / 2]);
  auto quantile = [&](double q) {
    const double at = q * static_cast<double>(s.size() - 1);
    const std::size_t i = static_cast<std::size_t>(at);
    const double f = at - static_cast<double>(i);
    return i + 1 < s.size() ? s[i] * (1.0 - f) + s[i + 1] * f : s[i];
  };
  st.q25 = quantile(0.25);
  st.q75 = quantile(0.75);
  st.mean = std::accumulate(s.begin(), s.end(), 0.0) / static_cast<double>(s.size());
  double var = 0;
  for (double v : s) var += (v - st.mean) * (v - st.mean);
  st.stddev = s.size() > 1 ? std::sqrt(var / static_cast<double>(s.size() - 1)) : 0.0;
  return st;
}

std::string format(const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  char buf[1024];
  std::vsnprintf(buf, sizeof(buf), fmt, args);
  va_end(args);
  return buf;
}

namespace {

// The comma-separated items of text, each read by parse; empty items are skipped.
template <typename T, typename Parse>
std::vector<T> list_of(const std::string& text, Parse parse) {
  std::vector<T> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (!item.empty()) out.push_back(parse(item));
  }
  return out;
}

}  // namespace

std::vector<double> number_list(const std::string& text) {
  return list_of<double>(text, [](const std::string& item) { return std::stod(item); });
}

std::vector<int> int_list(const std::string& text) {
  return list_of<int>(text, [](const std::string& item) { return std::stoi(item); });
}

nlohmann::json Stats::to_json() const {
  return {{"min", min}, {"q25", q25},   {"median", median}, {"q75", q75},
          {"max", max}, {"mean", mean}, {"stddev", stddev}};
}

std::string Options::output_dir(const std::string& key, const std::string& fallback) const {
  const std::string dir = get(key, fallback);
  if (!dir.empty()) std::filesystem::create_directories(dir);
  return dir;
}

std::string Options::get(const std::string& key, const std::string& fallback) const {
  read.insert(key);
  const auto it = extra.find(key);
  return it == extra.end() ? fallback : it->second;
}

int Options::get_int(const std::string& key, int fallback) const {
  read.insert(key);
  const auto it = extra.find(key);
  return it == extra.end() ? fallback : std::stoi(it->second);
}

double Options::get_double(const std::string& key, double fallback) const {
  read.insert(key);
  const auto it = extra.find(key);
  return it == extra.end() ? fallback : std::stod(it->second);
}

static std::vector<CaseEntry>& registry() {
  static std::vector<CaseEntry> entries;
  return entries;
}

void register_case(const std::string& name, const std::string& summary, CaseFn fn) {
  registry().push_back({name, summary, std::move(fn)});
}

const std::vector<CaseEntry>& cases() { return registry(); }

double time_ms(const std::function<void()>& fn) {
  const auto start = std::chrono::steady_clock::now();
  fn();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

nlohmann::json metadata(const DeviceInfo& device, const Options& options) {
  char date[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof(date), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  char host[256] = {0};
  gethostname(host, sizeof(host) - 1);
  std::string revision = "unknown";
  if (FILE* pipe = popen("git describe --always --dirty 2>/dev/null", "r")) {
    char buf[64] = {0};
    if (std::fgets(buf, sizeof(buf), pipe) != nullptr) {
      revision = buf;
      while (!revision.empty() && (revision.back() == '\n')) revision.pop_back();
    }
    pclose(pipe);
  }
  return {{"date", date},
          {"git", revision},
          {"host", host},
          {"cores", riner::usable_cores()},
          {"device", device.full_name()},
          {"driver", device.driver_version},
          {"settings",
           {{"size", options.size},
            {"runs", options.runs},
            {"warmup", options.warmup},
            {"device", options.device},
            {"options", options.extra}}}};
}

}  // namespace riner::bench
