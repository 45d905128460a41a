// How many slab processes riner starts when the user leaves it to riner (slab_processes.hpp).
#include <doctest/doctest.h>

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
}
