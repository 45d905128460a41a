// The CPU cores this process may run on. A batch job, a container's cpuset or `taskset` gives a
// process a share of the machine through its affinity mask; std::thread::hardware_concurrency
// and PoCL (3.1 and 5.0) count every core of the machine instead, so without this a process
// given 2 of 16 cores would start 16 threads on them.
#pragma once

namespace riner {

// The cores in this process's affinity mask (at least 1; the machine's count where the mask
// cannot be read).
unsigned usable_cores();

// Every core of the machine, whatever this process may use: what a plan that must not depend
// on how the machine is shared out (ranks, processes, affinity) is sized by.
unsigned machine_cores();

// Holds PoCL's CPU device to usable_cores() threads (POCL_MAX_PTHREAD_COUNT) where the user has
// not chosen a count (that, or POCL_CPU_MAX_CU_COUNT, POCL_MAX_COMPUTE_UNITS) and the process
// may not use every core.
// Takes effect only before OpenCL's platforms are first listed (riner's device listing calls it).
void fit_opencl_threads_to_usable_cores();

}  // namespace riner
