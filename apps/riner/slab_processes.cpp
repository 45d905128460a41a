#include "slab_processes.hpp"

#include <sched.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <fstream>
#include <iterator>
#include <thread>

#include "riner/cores.hpp"
#include "riner/error.hpp"
#include "stop_signal.hpp"

extern char** environ;

namespace riner::app {

namespace {

// This process's command line, word by word (Linux: /proc/self/cmdline).
std::vector<std::string> own_command_line() {
  std::ifstream in("/proc/self/cmdline", std::ios::binary);
  const std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::vector<std::string> words;
  std::string word;
  for (char c : all) {
    if (c == '\0') {
      words.push_back(word);
      word.clear();
    } else {
      word += c;
    }
  }
  if (words.empty()) throw Error("cannot read this process's command line (/proc/self/cmdline)");
  return words;
}

}  // namespace

int default_slab_processes(const std::string& device_type, unsigned cores,
                           std::size_t slabs_fitting) {
  if (device_type != "CPU" || cores <= 2) return 1;
  return static_cast<int>(std::clamp<std::size_t>(slabs_fitting, 1, cores / 2));
}

SlabProcesses::SlabProcesses(int count, int threads, const std::vector<std::string>& extra,
                             bool pin, std::vector<std::string> command) {
  const bool own = command.empty();
  std::vector<std::string> words = own ? own_command_line() : std::move(command);
  words.insert(words.end(), extra.begin(), extra.end());
  const std::string program = own ? "/proc/self/exe" : words.front();
  std::vector<cpu_set_t> masks;
  if (pin) {
    for (const std::vector<int>& group : core_groups(usable_core_ids(), count, threads)) {
      cpu_set_t set;
      CPU_ZERO(&set);
      for (int c : group) CPU_SET(c, &set);
      masks.push_back(set);
    }
  }
  pinned_ = !masks.empty();
  // Everything the child needs is built before fork: between fork and exec only
  // async-signal-safe calls (another thread may hold the allocator's lock).
  std::vector<std::string> environment;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry(*e);
    if (entry.rfind("POCL_MAX_PTHREAD_COUNT=", 0) == 0 || entry.rfind("RINER_THREADS=", 0) == 0) {
      continue;
    }
    environment.push_back(entry);
  }
  environment.push_back("POCL_MAX_PTHREAD_COUNT=" + std::to_string(threads));
  environment.push_back("RINER_THREADS=" + std::to_string(threads));
  std::vector<char*> argv, envp;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  for (std::string& e : environment) envp.push_back(e.data());
  envp.push_back(nullptr);
  static const char kExecFailed[] = "riner: error: cannot start a slab process (exec failed)\n";
  static const char kNotPinned[] = "riner: warning: a slab process runs unpinned\n";
  const pid_t parent = getpid();
  // Blocked from fork to the copy's own handler (stop_signal.cpp's end_cleanly_on_signals): a
  // stop request meanwhile waits instead of ending it.
  const sigset_t request = stop_request_set();
  for (int i = 0; i < count; ++i) {
    const pid_t pid = fork();
    if (pid < 0) {
      stop_all();
      throw Error("cannot start a slab process (fork failed)");
    }
    if (pid == 0) {
      // The child dies with its parent and runs this riner again with its share of the cores.
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (getppid() != parent) _exit(1);
      // sched_setaffinity and write allocate nothing: safe here.
      if (pinned_ &&
          sched_setaffinity(0, sizeof(cpu_set_t), &masks[static_cast<std::size_t>(i)]) != 0) {
        (void)!write(2, kNotPinned, sizeof(kNotPinned) - 1);
      }
      sigprocmask(SIG_BLOCK, &request, nullptr);
      execve(program.c_str(), argv.data(), envp.data());
      (void)!write(2, kExecFailed, sizeof(kExecFailed) - 1);
      _exit(127);
    }
    children_.push_back(pid);
  }
}

SlabProcesses::~SlabProcesses() { stop_all(); }

void SlabProcesses::stop_all() { signal_and_wait(SIGKILL); }

void SlabProcesses::signal_and_wait(int sig) {
  for (pid_t pid : children_) kill(pid, sig);
  for (pid_t pid : children_) {
    while (waitpid(pid, nullptr, 0) < 0 && errno == EINTR) {
    }
  }
  children_.clear();
}

void SlabProcesses::stop() { signal_and_wait(stop_request_signal()); }

bool SlabProcesses::running() {
  for (std::size_t i = 0; i < children_.size();) {
    int status = 0;
    const pid_t done = waitpid(children_[i], &status, WNOHANG);
    if (done == 0) {
      ++i;
      continue;
    }
    children_.erase(children_.begin() + static_cast<std::ptrdiff_t>(i));
    // A copy stopped by SIGTERM or SIGINT has saved its slab's checkpoint (stop_signal.hpp):
    // not a failure, and the others must not be killed mid-save.
    const int code = done > 0 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    const bool ok = code == 0 || code == 128 + SIGTERM || code == 128 + SIGINT;
    if (!ok && failure_.empty()) {
      failure_ = WIFSIGNALED(status)
                     ? "a slab process was killed (signal " + std::to_string(WTERMSIG(status)) + ")"
                     : "a slab process failed (exit " + std::to_string(WEXITSTATUS(status)) +
                           "; its message is above)";
      stop_all();
      return false;
    }
  }
  return !children_.empty();
}

}  // namespace riner::app
