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

namespace riner::app {

class RankStop {
 public:
  // From now on this process's stop is every rank's of the run `token`, through `folder`.
  // Before: its own signal only.
  void share(const std::filesystem::path& folder, const std::string& token);
  // This process's signal (which it then leaves for the others), or another rank's file. Called
  // by the training workers at each report.
  bool requested();
  // The signal that stopped the run (this process's or another's), or 0.
  int signal();

  // The stop files in `folder` of runs other than `token` (a stopped run's, once resumed);
  // every one when `token` is empty.
  static void remove_others(const std::filesystem::path& folder, const std::string& token);

 private:
  std::filesystem::path file_;  // empty until share()
  std::once_flag left_;
  std::atomic<int> from_other_{0};
};

}  // namespace riner::app
