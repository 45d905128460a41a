// How many slab processes riner starts when the user leaves it to riner (slab_processes.hpp).
#include <doctest/doctest.h>
#include <sched.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

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

  TEST_CASE("core groups: disjoint, in the mask's order, none when too few cores or one group") {
    using Groups = std::vector<std::vector<int>>;
    CHECK(riner::core_groups({0, 1, 2, 3, 4, 5}, 3, 2) == Groups{{0, 1}, {2, 3}, {4, 5}});
    CHECK(riner::core_groups({2, 5, 7}, 3, 1) == Groups{{2}, {5}, {7}});
    CHECK(riner::core_groups({0, 1, 2, 3, 4}, 2, 2) == Groups{{0, 1}, {2, 3}});
    CHECK(riner::core_groups({0, 1, 2, 3}, 3, 2).empty());
    CHECK(riner::core_groups({0, 1, 2, 3}, 1, 4).empty());  // one process: nothing to pin
    CHECK(riner::core_groups({}, 2, 1).empty());
  }

  TEST_CASE("riner's own slab processes run each on cores of its own, or where they like") {
    const std::vector<int> ids = riner::usable_core_ids();
    if (ids.size() < 2) {
      MESSAGE("one usable core: nothing to pin");
      return;
    }
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("riner_pin_" + std::to_string(getpid()));
    // Each copy writes the cores it may use (Linux: /proc/PID/status) to a file named by its pid.
    const auto cores_of_copies = [&](bool pin) {
      fs::remove_all(dir);
      fs::create_directories(dir);
      const std::string write_cores =
          "grep Cpus_allowed_list /proc/self/status | cut -f2 > " + dir.string() + "/$$";
      riner::app::SlabProcesses copies(2, 1, {}, pin, {"/bin/sh", "-c", write_cores});
      CHECK(copies.pinned() == pin);
      while (copies.running()) std::this_thread::sleep_for(std::chrono::milliseconds(10));
      CHECK(copies.failure().empty());
      std::vector<std::string> lists;
      for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
        std::ifstream in(e.path());
        std::string list;
        std::getline(in, list);
        lists.push_back(list);
      }
      fs::remove_all(dir);
      return lists;
    };
    const std::vector<std::string> pinned = cores_of_copies(true);
    REQUIRE(pinned.size() == 2);
    CHECK(std::set<std::string>(pinned.begin(), pinned.end()) ==
          std::set<std::string>{std::to_string(ids[0]), std::to_string(ids[1])});
    const std::vector<std::string> free = cores_of_copies(false);
    REQUIRE(free.size() == 2);
    CHECK(free[0] == free[1]);  // the parent's mask, whole
    CHECK(free[0] != pinned[0]);
  }
}
