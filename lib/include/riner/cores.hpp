// The CPU cores this process may run on. A batch job, a container's cpuset or `taskset` gives a
// process a share of the machine through its affinity mask; std::thread::hardware_concurrency
// and PoCL (3.1 and 5.0) count every core of the machine instead, so without this a process
// given 2 of 16 cores would start 16 threads on them.
#pragma once

#include <vector>

namespace riner {

// The cores in this process's affinity mask (at least 1; the machine's count where the mask
// cannot be read).
unsigned usable_cores();

// The ids of the cores in this process's affinity mask, in increasing order (empty where the
// mask cannot be read).
std::vector<int> usable_core_ids();

// `count` disjoint groups of `per_group` cores each, taken in the mask's order from `cores`:
// what each of `count` processes is pinned to. Empty, pin nothing, when fewer than two groups
// or too few cores.
std::vector<std::vector<int>> core_groups(const std::vector<int>& cores, int count, int per_group);

// Every core of the machine, whatever this process may use: what a plan that must not depend
// on how the machine is shared out (ranks, processes, affinity) is sized by.
unsigned machine_cores();

// Holds PoCL's CPU device to usable_cores() threads (POCL_MAX_PTHREAD_COUNT) where the user has
// not chosen a count (that, or POCL_CPU_MAX_CU_COUNT, POCL_MAX_COMPUTE_UNITS) and the process
// may not use every core.
// Takes effect only before OpenCL's platforms are first listed (riner's device listing calls it).
void fit_opencl_threads_to_usable_cores();

}  // namespace riner
