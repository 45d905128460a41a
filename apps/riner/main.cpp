// riner: ring artifact removal for CT. Dispatches to one subcommand per file (cmd_*.cpp).
// Exit codes: 0 success, 1 runtime failure, 2 bad usage or bad input.
#include <cstdio>
#include <cstring>
#include <exception>
#include <string>

#include "cli_args.hpp"
#include "commands.hpp"
#include "riner/error.hpp"
#include "riner/version.hpp"
#include "stop_signal.hpp"

namespace {

struct Command {
  const char* name;
  int (*run)(int, char**, int);
  const char* summary;
};

constexpr Command kCommands[] = {
    {"reconstruct", riner::app::run_reconstruct, "remove ring artifacts: train Riner on a scan"},
    {"demo", riner::app::run_demo, "simulate a ring scan, reconstruct it with FBP and Riner"},
    {"devices", riner::app::run_devices, "list OpenCL devices and their capabilities"},
    {"info", riner::app::run_info, "describe an array file or a geometry file"},
    {"simulate", riner::app::run_simulate, "simulate a ring-corrupted scan (paper protocol)"},
    {"fbp", riner::app::run_fbp, "filtered backprojection (FBP / FDK) of a scan"},
    {"center", riner::app::run_center, "estimate the centre of rotation from the scan"},
    {"destripe", riner::app::run_destripe,
     "classical stripe removal on the sinogram (Vo's methods), optionally with its FBP"},
    {"compare", riner::app::run_compare, "PSNR / SSIM / MAE of an image against a reference"},
    {"settings", riner::app::run_settings, "every reconstruct setting: default, range, meaning"},
};

void print_usage(std::FILE* out) {
  std::fprintf(out,
               "usage: riner <command> [arguments] [options]\n\n"
               "Removes ring artifacts from CT scans (Riner: an implicit neural representation\n"
               "trained per scan, with each detector element's response learned alongside).\n\n"
               "commands:\n");
  for (const Command& c : kCommands) std::fprintf(out, "  %-12s %s\n", c.name, c.summary);
  std::fprintf(out,
               "\n`riner <command> --help` describes a command; the guide, in the same order:\n"
               "docs/guide/command-line.md.\n"
               "Device choice: --device or RINER_DEVICE (index or name substring).\n");
}

int fail(int code, const std::string& message) {
  std::fprintf(stderr, "riner: error: %s\n", message.c_str());
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    print_usage(argc < 2 ? stderr : stdout);
    return argc < 2 ? 2 : 0;
  }
  if (std::strcmp(argv[1], "--version") == 0) {
    std::printf("riner %s\n", RINER_VERSION);
    return 0;
  }
  const Command* command = nullptr;
  for (const Command& c : kCommands) {
    if (std::strcmp(argv[1], c.name) == 0) command = &c;
  }
  if (command == nullptr) {
    return fail(2, std::string("unknown command '") + argv[1] + "' (see riner --help)");
  }
  riner::app::end_cleanly_on_signals();
  try {
    return command->run(argc, argv, 2);
  } catch (const riner::app::UsageError& e) {
    return fail(2, std::string(e.what()) + " (see riner " + command->name + " --help)");
  } catch (const riner::InputError& e) {
    return fail(2, e.what());
  } catch (const riner::BuildError& e) {
    std::fprintf(stderr, "%s\n", e.log().c_str());
    return fail(1, std::string(e.what()) + " with options " + e.options());
  } catch (const std::bad_alloc&) {
    return fail(1, "out of memory");
  } catch (const std::exception& e) {
    return fail(1, e.what());
  }
}
