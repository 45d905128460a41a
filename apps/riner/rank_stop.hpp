// A stop one process of a slabbed run asks of every process: an MPI rank or a --processes copy
// stopped by its own signal (SIGTERM to its process alone, a node being drained) leaves
// slabs/stop.TOKEN holding the signal's number, and every process's training looks for it at its
// reports, saves its slab's checkpoint and stops. So MPI ranks still meet at the end and finish
// MPI together, whichever launcher started them (a rank that left alone would have Open MPI
// SIGKILL the others a second after its SIGTERM, mid-save perhaps; under srun the others could
// wait for it to the job's time limit), and the run ends as a stopped run, not as one whose
// other processes trained on and then found a slab missing.
#pragma once

#include <atomic>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>

namespace riner::app {

class RankStop {
 public:
  RankStop() = default;
  ~RankStop();
  RankStop(const RankStop&) = delete;
  RankStop& operator=(const RankStop&) = delete;

  // From now on this process's stop is every process's of the run `token`, through `folder`:
  // a watcher leaves the file as soon as this process's signal comes, whatever it is doing (a
  // rank with no slab left waits for the others in MPI, where no report looks). Before: its
  // own signal only.
  void share(const std::filesystem::path& folder, const std::string& token);
  // This process's signal, or another's file. Called by the training workers at each report.
  bool requested();
  // The signal that stopped the run (this process's or another's), or 0; looks once more.
  int signal();

  // The stop files in `folder` of runs other than `token` (a stopped run's, once resumed);
  // every one when `token` is empty.
  static void remove_others(const std::filesystem::path& folder, const std::string& token);

 private:
  void leave_file(int sig);     // once; never throws (a stop must not become an error)
  std::filesystem::path file_;  // empty until share(), then fixed
  std::once_flag left_;
  std::atomic<int> from_other_{0};
  std::atomic<bool> done_{false};
  std::thread watcher_;
};

}  // namespace riner::app
