// SIGTERM (a batch scheduler's notice before its SIGKILL) and SIGINT (Ctrl-C) during training:
// the training saves its checkpoint at the next report and stops, so `--resume` loses nothing.
// A second signal, or one outside training, ends the process at once, and removes the
// temporary files of the writes it interrupts (riner::remove_unfinished_outputs): a stopped
// run leaves its outputs whole or absent, nothing half-written beside them. A stop request
// (stop_request_signal()) asks for the same stop as SIGTERM and never ends the process at
// once: the first process of a --processes run sends it to its copies (slab_processes.hpp).
#pragma once

#include <signal.h>

#include <string>

namespace riner::app {

// For the whole process: SIGTERM, SIGINT and SIGHUP end it as their default action does, with
// the unfinished outputs removed first; a stop request sets stop_signal() to SIGTERM.
void end_cleanly_on_signals();
// The stop request: a real-time signal, which no library here takes; the set of it alone.
int stop_request_signal();
sigset_t stop_request_set();
// Installs the handlers while a command trains; release_stop_signals() hands SIGTERM and SIGINT
// back to end_cleanly_on_signals' handler.
void catch_stop_signals();
void release_stop_signals();
// The signal that asked to stop (SIGTERM or SIGINT), or 0.
int stop_signal();
// After a stop: "riner: stopped by SIG...: <what was kept>; the same command with --resume goes
// on" on stderr, and the exit code 128 + the signal's number.
int stopped_by_signal(const std::string& kept);
// The same for a stop by `sig` (another rank's, say).
int stopped_by_signal(const std::string& kept, int sig);

}  // namespace riner::app
