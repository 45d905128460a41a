// A stop one rank of an MPI run asks of every rank: a rank stopped by its own signal (SIGTERM to
// its process alone, a node being drained) leaves slabs/stop.TOKEN holding the signal's number,
// and every rank's training looks for it at its reports, saves its slab's checkpoint and stops.
// So the ranks still meet at the end and finish MPI together, whichever launcher started them
// (a rank that left alone would have Open MPI SIGKILL the others a second after its SIGTERM,
// mid-save perhaps; under srun the others could wait for it to the job's time limit).
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
  // The signal that stopped the run (this process's or another rank's), or 0.
  int signal() const;

  // The stop files in `folder` of runs other than `token` (a stopped run's, once resumed).
  static void remove_others(const std::filesystem::path& folder, const std::string& token);

 private:
  std::filesystem::path file_;  // empty until share()
  std::once_flag left_;
  std::atomic<int> from_other_{0};
};

}  // namespace riner::app
