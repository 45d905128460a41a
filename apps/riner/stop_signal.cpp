#include "stop_signal.hpp"

#include <signal.h>

#include <csignal>
#include <cstdio>

#include "riner/io.hpp"

namespace riner::app {

namespace {

volatile std::sig_atomic_t requested = 0;

// Only async-signal-safe calls: unlink (in remove_unfinished_outputs), sigaction, raise.
void end_now(int sig) {
  remove_unfinished_outputs();
  struct sigaction action {};
  action.sa_handler = SIG_DFL;
  sigemptyset(&action.sa_mask);
  sigaction(sig, &action, nullptr);
  raise(sig);  // pending until this handler returns, then the default action
}

// A signal the process was started ignoring (SIGHUP under nohup, SIGINT in a background job of
// a script) stays ignored.
void handle(int sig, void (*handler)(int)) {
  struct sigaction current {};
  if (sigaction(sig, nullptr, &current) == 0 && current.sa_handler == SIG_IGN) return;
  struct sigaction action {};
  action.sa_handler = handler;
  action.sa_flags = SA_RESTART;  // a wait for the slab processes goes on through a signal
  sigemptyset(&action.sa_mask);
  sigaction(sig, &action, nullptr);
}

void on_stop_signal(int sig) {
  requested = sig;
  // The second signal, either of the two, is not waited on.
  handle(SIGTERM, end_now);
  handle(SIGINT, end_now);
}

// A stop asked by the first process of a --processes run: as SIGTERM, but never at once.
void on_forwarded_stop(int) {
  if (requested == 0) requested = SIGTERM;
}

}  // namespace

// Not SIGUSR1 or SIGUSR2: LLVM (in PoCL's compiler) takes both when the device is opened, and
// its SIGUSR1 handler does not pass the signal on.
int stop_request_signal() { return SIGRTMIN + 1; }

sigset_t stop_request_set() {
  sigset_t request;
  sigemptyset(&request);
  sigaddset(&request, stop_request_signal());
  return request;
}

void end_cleanly_on_signals() {
  for (int sig : {SIGTERM, SIGINT, SIGHUP}) handle(sig, end_now);
  handle(stop_request_signal(), on_forwarded_stop);
  // A slab process starts with the request blocked (slab_processes.cpp): one sent before this
  // handler existed waits for it here instead of ending the process.
  const sigset_t request = stop_request_set();
  sigprocmask(SIG_UNBLOCK, &request, nullptr);
}

void catch_stop_signals() {
  handle(SIGTERM, on_stop_signal);
  handle(SIGINT, on_stop_signal);
  handle(stop_request_signal(), on_forwarded_stop);
}

void release_stop_signals() {
  handle(SIGTERM, end_now);
  handle(SIGINT, end_now);
}

int stop_signal() { return requested; }

int stopped_by_signal(const std::string& kept) { return stopped_by_signal(kept, stop_signal()); }

int stopped_by_signal(const std::string& kept, int sig) {
  std::fprintf(stderr, "riner: stopped by %s: %s; the same command with --resume goes on\n",
               sig == SIGINT    ? "SIGINT"
               : sig == SIGTERM ? "SIGTERM"
                                : "a signal",
               kept.c_str());
  return 128 + sig;
}

}  // namespace riner::app
