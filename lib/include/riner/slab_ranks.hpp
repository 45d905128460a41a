// The processes one slabbed run (riner/slab_run.hpp) is spread over: the ranks of an MPI job
// when riner was started by mpirun (and built with Open MPI), else this process alone. Slabs
// are handed out dynamically by claims on the shared output folder (slabs/slab_NNNN.TOKEN.claim,
// created exclusively, TOKEN new for each run): a slow rank takes fewer slabs and none waits for
// another. MPI itself starts the ranks together, shares rank 0's word (the run's token, or its
// error) and waits for all at the end; it is used nowhere else in riner.
#pragma once

#include <filesystem>
#include <string>

#include "riner/slab_run.hpp"

namespace riner {

class SlabRanks {
 public:
  // Joins the MPI job when the environment says mpirun started this process; otherwise (or
  // without MPI in the build) a job of one.
  SlabRanks();
  ~SlabRanks();
  SlabRanks(const SlabRanks&) = delete;
  SlabRanks& operator=(const SlabRanks&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  // This rank among those on its machine: which GPU, or which share of the cores, is its.
  int local_rank() const { return local_rank_; }
  int local_size() const { return local_size_; }
  bool is_leader() const { return rank_ == 0; }
  static bool built_with_mpi();
  // How many processes mpirun says it started together with this one (1 when it did not),
  // read from the environment, with or without MPI in the build.
  static int launched_size();

  // Rank 0's text, on every rank.
  std::string share(const std::string& from_leader) const;
  // Waits for every rank; true on all of them when every rank passed true.
  bool all_ok(bool ok) const;
  // Ends the job at once on every rank (a rank that failed alone would hang the others).
  [[noreturn]] void abort(int code) const;

 private:
  bool mpi_ = false;
  int rank_ = 0;
  int size_ = 1;
  int local_rank_ = 0;
  int local_size_ = 1;
};

// A fresh token for a run's claims (time and process id).
std::string new_claim_token();

// SlabRun's claim: true for the one process that creates the slab's claim file first.
SlabRun::Claim claim_by_file(const std::filesystem::path& out, const std::string& token);

}  // namespace riner
