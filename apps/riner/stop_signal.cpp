#include "stop_signal.hpp"

#include <signal.h>

#include <csignal>
#include <cstdio>

namespace riner::app {

namespace {

volatile std::sig_atomic_t requested = 0;

void on_stop_signal(int sig) {
  requested = sig;
  std::signal(sig, SIG_DFL);  // async-signal-safe; the second signal is not caught
}

}  // namespace

void catch_stop_signals() {
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGTERM, &action, nullptr);
  sigaction(SIGINT, &action, nullptr);
}

void release_stop_signals() {
  std::signal(SIGTERM, SIG_DFL);
  std::signal(SIGINT, SIG_DFL);
}

int stop_signal() { return requested; }

int stopped_by_signal(const std::string& kept) {
  const int sig = stop_signal();
  std::fprintf(stderr, "riner: stopped by %s: %s; the same command with --resume goes on\n",
               sig == SIGINT    ? "SIGINT"
               : sig == SIGTERM ? "SIGTERM"
                                : "a signal",
               kept.c_str());
  return 128 + sig;
}

}  // namespace riner::app
