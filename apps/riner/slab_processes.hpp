// The CLI's own way to fill a CPU's cores with a slabbed run, without mpirun: the process that
// planned the run starts N copies of its command line, each joining the run (--join-run TOKEN)
// with its share of the cores (POCL_MAX_PTHREAD_COUNT, RINER_THREADS), and each claims slabs
// as MPI ranks do (riner/slab_ranks.hpp's claims). PoCL shares one pool of threads among a
// process's queues and can abort with several at once, so processes, not queues, fill a CPU:
// 8 processes of 2 cores gave 5.5x the slices per minute of one on 16 cores
// (docs/history/RESULTS.md, "Issue 30: throughput"; each process pinned by taskset there). The
// copies die with the process that started them.
#pragma once

#include <string>
#include <sys/types.h>
#include <vector>

namespace riner::app {

class SlabProcesses {
 public:
  // Starts `count` copies of this process's command line plus `extra` words, each with
  // `threads` threads and, when `pin` and this process's cores hold `count` groups of
  // `threads` (riner::core_groups), pinned to a group of its own. `command` (a program's
  // absolute path and its words) replaces this process's command line: for tests. Error when one
  // cannot be started (those started are stopped).
  SlabProcesses(int count, int threads, const std::vector<std::string>& extra, bool pin,
                std::vector<std::string> command = {});
  ~SlabProcesses();  // stops those still running
  SlabProcesses(const SlabProcesses&) = delete;
  SlabProcesses& operator=(const SlabProcesses&) = delete;

  // True while any is running; a failed one stops the others and is named by failure().
  bool running();
  // A stop: the stop request to each (stop_signal.hpp: it saves its slab's checkpoint at the
  // next report and ends, as on SIGTERM, but a second request never ends it at once, so it is
  // safe when the terminal's Ctrl-C reached the copies too), then waits for them all.
  void stop();
  const std::string& failure() const { return failure_; }
  bool pinned() const { return pinned_; }

 private:
  void stop_all();
  void signal_and_wait(int sig);  // to every child still running
  std::vector<pid_t> children_;
  std::string failure_;
  bool pinned_ = false;
};

// How many processes a slabbed run on this device takes when the user leaves it to riner:
// one per two cores on a CPU with more than two, else one; never more than the slabs of one
// slice that fit the memory limit together (`slabs_fitting`, at least 1), since each process
// trains a slab of its own.
int default_slab_processes(const std::string& device_type, unsigned cores,
                           std::size_t slabs_fitting);

}  // namespace riner::app
