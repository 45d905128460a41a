// Running the riner executable from a test: its exit code, stdout and stderr, and the small
// simulated scans several CLI suites start from.
#pragma once

#include <doctest/doctest.h>

#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "support/fixture.hpp"

extern char** environ;

namespace riner::test {

struct Run {
  int code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

// `riner ARGUMENTS`, its stderr kept in dir/stderr.txt.
inline Run riner_cli(const std::string& arguments, const TempDir& dir) {
  const std::string err_file = (dir / "stderr.txt").string();
  const std::string command = std::string(RINER_CLI_PATH) + " " + arguments + " 2>" + err_file;
  Run run;
  FILE* pipe = popen(command.c_str(), "r");
  REQUIRE(pipe != nullptr);
  std::array<char, 4096> buffer;
  std::size_t n;
  while ((n = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) run.out.append(buffer.data(), n);
  const int status = pclose(pipe);
  run.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.err = read_bytes(err_file);
  return run;
}

// Who run_program_until's signal goes to: the process, the process group it leads (what a
// terminal's Ctrl-C reaches: the process and every process it started), or one of the
// processes it started (the first found; a slabbed run's --processes copy, say).
enum class SignalTo { kProcess, kGroup, kOneChild };

// The PID of the first running process whose /proc folder `matches`, or 0.
inline pid_t first_process(const std::function<bool(const std::filesystem::path&)>& matches) {
  std::error_code ignored;
  for (const auto& entry : std::filesystem::directory_iterator("/proc", ignored)) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    if (matches(entry.path())) return std::stoi(name);
  }
  return 0;
}

// A running child of `parent`, or 0 when it has none.
inline pid_t child_process(pid_t parent) {
  const std::string wanted = "PPid:\t" + std::to_string(parent) + "\n";
  return first_process([&](const std::filesystem::path& proc) {
    return read_bytes(proc / "status").find(wanted) != std::string::npos;
  });
}

// PROGRAM WORDS... (PROGRAM found on PATH) started and sent `sig` once `until` is true (or after
// 120 s), unless it ended first; the process's wait status.
inline int run_program_until(const std::string& program, std::vector<std::string> words,
                             const std::function<bool()>& until, int sig = SIGKILL,
                             SignalTo to = SignalTo::kProcess) {
  words.insert(words.begin(), program);
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  // The signals at their defaults and none blocked, whatever this process inherited (a job
  // started in the background of a script ignores SIGINT, and so would its children).
  sigset_t defaults, none;
  sigemptyset(&defaults);
  for (int s : {SIGINT, SIGTERM, SIGHUP}) sigaddset(&defaults, s);
  sigemptyset(&none);
  posix_spawnattr_setsigdefault(&attributes, &defaults);
  posix_spawnattr_setsigmask(&attributes, &none);
  short flags = POSIX_SPAWN_SETSIGDEF | POSIX_SPAWN_SETSIGMASK;
  if (to == SignalTo::kGroup) {
    flags |= POSIX_SPAWN_SETPGROUP;
    posix_spawnattr_setpgroup(&attributes, 0);  // a group of its own, led by it
  }
  posix_spawnattr_setflags(&attributes, flags);
  pid_t pid = 0;
  const int spawned =
      posix_spawnp(&pid, program.c_str(), nullptr, &attributes, argv.data(), environ);
  posix_spawnattr_destroy(&attributes);
  REQUIRE(spawned == 0);
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  int status = 0;
  while (!until() && std::chrono::steady_clock::now() < deadline) {
    if (waitpid(pid, &status, WNOHANG) == pid) return status;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  if (to == SignalTo::kOneChild) {
    pid_t child = 0;
    while ((child = child_process(pid)) == 0 && waitpid(pid, &status, WNOHANG) == 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    if (child > 0) kill(child, sig);
  } else {
    kill(to == SignalTo::kGroup ? -pid : pid, sig);
  }
  waitpid(pid, &status, 0);
  return status;
}

// The same for `riner WORDS...`.
inline int run_until(std::vector<std::string> words, const std::function<bool()>& until,
                     int sig = SIGKILL) {
  return run_program_until(RINER_CLI_PATH, std::move(words), until, sig);
}

// The PID of a process that has ended (`true`, waited for): it names no running writer.
inline pid_t ended_process_id() {
  pid_t pid = 0;
  char name[] = "true";
  char* argv[] = {name, nullptr};
  REQUIRE(posix_spawnp(&pid, "true", nullptr, nullptr, argv, environ) == 0);
  waitpid(pid, nullptr, 0);
  return pid;
}

// The PID of riner running as MPI rank `rank` with `marker` among its arguments (its output
// folder, say), from /proc; 0 when there is none.
inline pid_t mpi_rank_process(int rank, const std::string& marker) {
  const std::string wanted = "OMPI_COMM_WORLD_RANK=" + std::to_string(rank);
  return first_process([&](const std::filesystem::path& proc) {
    const std::string arguments = read_bytes(proc / "cmdline");
    if (arguments.rfind(std::string(RINER_CLI_PATH) + '\0', 0) != 0 ||
        arguments.find(marker) == std::string::npos) {
      return false;
    }
    const std::string environment = read_bytes(proc / "environ");
    std::size_t at = 0;
    for (std::size_t end; (end = environment.find('\0', at)) != std::string::npos; at = end + 1) {
      if (environment.compare(at, end - at, wanted) == 0) return true;
    }
    return false;
  });
}

// The temporary files (".tmp." in the name) anywhere under `folder`.
inline std::vector<std::string> temporary_files(const std::filesystem::path& folder) {
  std::vector<std::string> found;
  std::error_code ignored;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(folder, ignored)) {
    if (entry.path().filename().string().find(".tmp.") != std::string::npos) {
      found.push_back(entry.path().string());
    }
  }
  return found;
}

// `geometry_json` written as dir/geometry_file and `riner simulate --quiet OPTIONS` of it into
// dir/sim; returns dir/sim.
inline std::string simulate_geometry(const TempDir& dir, const std::string& geometry_file,
                                     const std::string& geometry_json, const std::string& options) {
  write_bytes(dir / geometry_file, geometry_json);
  const std::string sim = (dir / "sim").string();
  REQUIRE(riner_cli("simulate --quiet " + options + " --geometry " +
                        (dir / geometry_file).string() + " --out " + sim,
                    dir)
              .code == 0);
  return sim;
}

// A small parallel-beam slice (90 views over 180 degrees, 70 elements, a 64 x 64 grid)
// simulated into dir/sim with `seed`, its geometry in dir/g2.json; returns dir/sim.
inline std::string simulate_small_parallel2d(const TempDir& dir, int seed) {
  return simulate_geometry(dir, "g2.json", R"({"type": "parallel2d",
      "detector": {"count": 70, "pitch_mm": 1.0},
      "angles": {"count": 90, "range_rad": 3.141592653589793},
      "volume": {"shape": [64, 64], "voxel_mm": 1.0}})",
                           "--seed " + std::to_string(seed));
}

// A small parallel-beam stack (36 views, 30 x 20 detector, 20 x 24 x 24 volume) simulated into
// dir/sim, its geometry in dir/g3.json; returns dir/sim.
inline std::string simulate_small_parallel3d(const TempDir& dir) {
  return simulate_geometry(dir, "g3.json", R"({"type": "parallel3d",
      "detector": {"count": [30, 20], "pitch_mm": [1.0, 1.0]},
      "angles": {"count": 36, "range_rad": 3.141592653589793},
      "volume": {"shape": [20, 24, 24], "voxel_mm": 1.0}})",
                           "--seed 3");
}

}  // namespace riner::test
