#include "progress.hpp"

#include <unistd.h>

#include <cstdio>
#include <string>

namespace riner::app {

std::string format_duration(double seconds) {
  char buf[32];
  if (seconds < 60.0) {
    std::snprintf(buf, sizeof(buf), "%.1fs", seconds);
  } else if (seconds < 3600.0) {
    std::snprintf(buf, sizeof(buf), "%dm%02ds", static_cast<int>(seconds) / 60,
                  static_cast<int>(seconds) % 60);
  } else {
    std::snprintf(buf, sizeof(buf), "%dh%02dm", static_cast<int>(seconds) / 3600,
                  static_cast<int>(seconds) / 60 % 60);
  }
  return buf;
}

Progress::Progress(std::string label, std::size_t total, bool quiet, bool counts)
    : label_(std::move(label)),
      total_(total),
      quiet_(quiet),
      counts_(counts),
      tty_(::isatty(STDERR_FILENO) != 0),
      start_(Clock::now()),
      last_draw_(start_) {}

Progress::~Progress() {
  // A bar left mid-line would swallow the next message.
  if (tty_ && !quiet_ && !finished_) std::fputc('\n', stderr);
}

void Progress::update(std::size_t done, const std::string& status) {
  if (quiet_) return;
  const auto now = Clock::now();
  const auto min_interval = tty_ ? std::chrono::milliseconds(100) : std::chrono::seconds(5);
  if (now - last_draw_ < min_interval && done < total_) return;
  last_draw_ = now;
  draw(done, status, false);
}

void Progress::finish(const std::string& status) {
  if (quiet_ || finished_) return;
  finished_ = true;
  draw(total_, status, true);
}

void Progress::draw(std::size_t done, const std::string& status, bool final_line) {
  const double elapsed = std::chrono::duration<double>(Clock::now() - start_).count();
  const double fraction =
      total_ > 0 ? static_cast<double>(done) / static_cast<double>(total_) : 1.0;
  std::string eta = final_line ? "took " + format_duration(elapsed)
                    : done > 0 ? "ETA " + format_duration(elapsed * (1.0 / fraction - 1.0))
                               : "ETA ?";
  const std::string count =
      counts_ ? " " + std::to_string(done) + "/" + std::to_string(total_) : std::string();
  if (tty_) {
    constexpr int kWidth = 28;
    const int filled = static_cast<int>(fraction * kWidth + 0.5);
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar.resize(kWidth, '.');
    std::fprintf(stderr, "\r\033[K%s [%s] %3d%%%s %s %s", label_.c_str(), bar.c_str(),
                 static_cast<int>(fraction * 100.0 + 0.5), count.c_str(), eta.c_str(),
                 status.c_str());
    if (final_line) std::fputc('\n', stderr);
  } else {
    std::fprintf(stderr, "%s:%s (%d%%) %s %s\n", label_.c_str(), count.c_str(),
                 static_cast<int>(fraction * 100.0 + 0.5), eta.c_str(), status.c_str());
  }
  std::fflush(stderr);
}

}  // namespace riner::app
