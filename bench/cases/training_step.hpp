// The training step as a reconstruction runs it, timed per execution plan: shared by the
// `training_step` case and the `ops` table.
#pragma once

#include <string>
#include <vector>

#include "harness.hpp"
#include "peak.hpp"

namespace riner::bench {

// Rows for each plan ("cpu", "gpu" or "" for the device's own) and rays per step (0: the
// default) on the paper geometry; with peaks, GFLOP/s as a share of them.
std::vector<Result> time_training_steps(const Device& device, const Options& o,
                                        const std::vector<std::string>& plans,
                                        const std::vector<int>& rays, const Peaks* peaks);

}  // namespace riner::bench
