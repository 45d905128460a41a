// The riner subcommands. Each parses its own arguments (from argv[first]) and returns the
// process exit code; errors are thrown and mapped to exit codes in main.cpp.
#pragma once

#include <string>

#include "cli_args.hpp"
#include "riner/destripe.hpp"

namespace riner::app {

int run_devices(int argc, char** argv, int first);
int run_info(int argc, char** argv, int first);
int run_simulate(int argc, char** argv, int first);
int run_fbp(int argc, char** argv, int first);
int run_compare(int argc, char** argv, int first);
int run_reconstruct(int argc, char** argv, int first);
int run_demo(int argc, char** argv, int first);
int run_settings(int argc, char** argv, int first);
int run_center(int argc, char** argv, int first);
int run_destripe(int argc, char** argv, int first);

// The stripe filter's tuning options (--size, --large-size, --snr, --sigma), shared by destripe
// and fbp --destripe, and the options they name with `method`.
void add_destripe_tuning(Args& args);
DestripeOptions destripe_options_from(const Args& args, const std::string& method);

}  // namespace riner::app
