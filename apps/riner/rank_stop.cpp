#include "rank_stop.hpp"

#include <csignal>
#include <string>

#include "riner/io.hpp"
#include "stop_signal.hpp"

namespace riner::app {

namespace {

constexpr const char* kPrefix = "stop.";

}  // namespace

void RankStop::share(const std::filesystem::path& folder, const std::string& token) {
  file_ = folder / (kPrefix + token);
}

bool RankStop::requested() {
  if (const int own = stop_signal(); own != 0) {
    if (!file_.empty()) {
      std::call_once(left_, [&] { write_text(file_, std::to_string(own)); });
    }
    return true;
  }
  if (from_other_ != 0) return true;
  std::error_code missing;
  if (file_.empty() || !std::filesystem::exists(file_, missing)) return false;
  int sig = SIGTERM;  // a file being renamed into place reads as SIGTERM's stop
  try {
    sig = std::stoi(read_text(file_));
  } catch (const std::exception&) {
  }
  from_other_ = sig > 0 ? sig : SIGTERM;
  return true;
}

int RankStop::signal() {
  if (!requested()) return 0;  // looks once more: the others may have stopped since
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
