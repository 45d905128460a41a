// SIGTERM (a batch scheduler's notice before its SIGKILL) and SIGINT (Ctrl-C) during training:
// the training saves its checkpoint at the next report and stops, so `--resume` loses nothing.
// A second signal ends the process at once.
#pragma once

#include <string>

namespace riner::app {

// Installs the handlers while a command trains; release_stop_signals() gives both signals
// their default action back (a signal after training ends the process as usual).
void catch_stop_signals();
void release_stop_signals();
// The signal that asked to stop (SIGTERM or SIGINT), or 0.
int stop_signal();
// After a stop: "riner: stopped by SIG...: <what was kept>; the same command with --resume goes
// on" on stderr, and the exit code 128 + the signal's number.
int stopped_by_signal(const std::string& kept);

}  // namespace riner::app
