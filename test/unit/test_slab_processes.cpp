// How many slab processes riner starts when the user leaves it to riner (slab_processes.hpp).
#include <doctest/doctest.h>
#include <sched.h>

#include <cstdlib>
#include <string>

#include "riner/cores.hpp"
#include "slab_processes.hpp"

TEST_SUITE("slab processes") {
  TEST_CASE("one per two cores on a CPU, one elsewhere, never more than the memory holds") {
    using riner::app::default_slab_processes;
    CHECK(default_slab_processes("CPU", 2, 100) == 1);
    CHECK(default_slab_processes("CPU", 16, 100) == 8);
    CHECK(default_slab_processes("CPU", 17, 100) == 8);
    CHECK(default_slab_processes("GPU", 16, 100) == 1);
    // Each process trains a slab of its own: 3 slabs of one slice fit, so 3 processes.
    CHECK(default_slab_processes("CPU", 16, 3) == 3);
    CHECK(default_slab_processes("CPU", 16, 0) == 1);  // not even one fits: still one
  }

  TEST_CASE("a process held to one core by its affinity counts one, and PoCL is told so") {
    cpu_set_t saved;
    REQUIRE(sched_getaffinity(0, sizeof(saved), &saved) == 0);
    int first = 0;
    while (!CPU_ISSET(first, &saved)) ++first;
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(first, &one);
    REQUIRE(sched_setaffinity(0, sizeof(one), &one) == 0);
    const unsigned usable = riner::usable_cores();
    const char* before = std::getenv("POCL_MAX_PTHREAD_COUNT");
    const bool user_chose = before != nullptr || std::getenv("POCL_CPU_MAX_CU_COUNT") != nullptr ||
                            std::getenv("POCL_MAX_COMPUTE_UNITS") != nullptr;
    riner::fit_opencl_threads_to_usable_cores();
    const char* after = std::getenv("POCL_MAX_PTHREAD_COUNT");
    const std::string told = after ? after : "";
    if (!user_chose && riner::machine_cores() > 1) {
      unsetenv("POCL_MAX_PTHREAD_COUNT");
    }
    REQUIRE(sched_setaffinity(0, sizeof(saved), &saved) == 0);
    CHECK(usable == 1);
    CHECK(riner::usable_cores() == static_cast<unsigned>(CPU_COUNT(&saved)));
    CHECK(riner::machine_cores() >= riner::usable_cores());
    if (!user_chose && riner::machine_cores() > 1) CHECK(told == "1");
  }
}
