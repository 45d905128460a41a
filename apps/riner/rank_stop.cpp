#include "rank_stop.hpp"

#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <string>

#include "riner/io.hpp"
#include "stop_signal.hpp"

namespace riner::app {

namespace {

constexpr const char* kPrefix = "stop.";
constexpr auto kWatchEvery = std::chrono::milliseconds(100);

}  // namespace

RankStop::~RankStop() {
  done_ = true;
  if (watcher_.joinable()) watcher_.join();
}

void RankStop::share(const std::filesystem::path& folder, const std::string& token) {
  file_ = folder / (kPrefix + token);
  watcher_ = std::thread([this] {
    while (!done_) {
      if (const int own = stop_signal(); own != 0) {
        leave_file(own);
        return;
      }
      std::this_thread::sleep_for(kWatchEvery);
    }
  });
}

void RankStop::leave_file(int sig) {
  std::call_once(left_, [&] {
    if (from_other_ != 0) return;  // another's is there already
    try {
      write_text(file_, std::to_string(sig));
    } catch (const std::exception& e) {
      // The others then stop only by their own signals; this process still stops.
      std::fprintf(stderr, "riner: warning: %s: the stop was not passed on\n", e.what());
    }
  });
}

bool RankStop::requested() {
  if (const int own = stop_signal(); own != 0) {
    if (!file_.empty()) leave_file(own);
    return true;
  }
  if (from_other_ != 0) return true;
  std::error_code missing;
  if (file_.empty() || !std::filesystem::exists(file_, missing)) return false;
  // Read as a plain file: riner::read_text would count it among this process's inputs, which
  // it then refuses to overwrite.
  int sig = 0;
  std::ifstream(file_) >> sig;
  from_other_ = sig > 0 ? sig : SIGTERM;  // unreadable (removed since, say): SIGTERM's stop
  return true;
}

int RankStop::signal() {
  if (!requested()) return 0;
  const int own = stop_signal();
  return own != 0 ? own : from_other_.load();
}

void RankStop::remove_others(const std::filesystem::path& folder, const std::string& token) {
  std::error_code error;
  for (const auto& entry : std::filesystem::directory_iterator(folder, error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(kPrefix, 0) == 0 && name != kPrefix + token) {
      std::filesystem::remove(entry.path(), error);
    }
  }
}

}  // namespace riner::app
