// Progress on stderr: a bar with ETA on a terminal, a log line every few seconds otherwise
// (so CI logs and redirected runs stay readable), nothing with --quiet.
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace riner::app {

class Progress {
 public:
  // `counts`: draw done/total; off where the status says what was done in its own units.
  Progress(std::string label, std::size_t total, bool quiet, bool counts = true);
  ~Progress();

  void update(std::size_t done, const std::string& status = "");
  void finish(const std::string& status = "");

 private:
  using Clock = std::chrono::steady_clock;
  void draw(std::size_t done, const std::string& status, bool final_line);

  std::string label_;
  std::size_t total_;
  bool quiet_;
  bool counts_;
  bool tty_;
  bool finished_ = false;
  Clock::time_point start_;
  Clock::time_point last_draw_;
};

// "1m05s", "12.3s"
std::string format_duration(double seconds);

}  // namespace riner::app
