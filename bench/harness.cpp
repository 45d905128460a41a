#include "harness.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <numeric>

namespace riner::bench {

Stats Stats::of(std::vector<double> s) {
  Stats st;
  if (s.empty()) return st;
  std::sort(s.begin(), s.end());
  st.min = s.front();
  st.max = s.back();
  st.median = s.size() % 2 ? s[s.size() / 2] : 0.5 * (s[s.size() / 2 - 1] + s[s.size() / 2]);
  st.mean = std::accumulate(s.begin(), s.end(), 0.0) / static_cast<double>(s.size());
  double var = 0;
  for (double v : s) var += (v - st.mean) * (v - st.mean);
  st.stddev = s.size() > 1 ? std::sqrt(var / static_cast<double>(s.size() - 1)) : 0.0;
  return st;
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

nlohmann::json metadata(const std::string& device_name) {
  char date[32];
  const std::time_t now = std::time(nullptr);
  std::strftime(date, sizeof(date), "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&now));
  char host[256] = {0};
  gethostname(host, sizeof(host) - 1);
  std::string revision = "unknown";
  if (FILE* pipe = popen("git rev-parse --short HEAD 2>/dev/null", "r")) {
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
          {"cores", sysconf(_SC_NPROCESSORS_ONLN)},
          {"device", device_name}};
}

}  // namespace riner::bench
