// A slabbed run's memory on its busiest machine, from the slab records (slab_run.hpp).
#include <doctest/doctest.h>

#include <nlohmann/json.hpp>

#include "riner/slab_run.hpp"

TEST_SUITE("slab machine peak") {
  TEST_CASE("each process's peak, summed per host, over this invocation's records") {
    const auto record = [](const char* process, std::size_t peak, double finished) {
      return nlohmann::json{{"process", process}, {"peak_host_bytes", peak},
                            {"finished_unix", finished}};
    };
    nlohmann::json slabs = nlohmann::json::array();
    slabs.push_back(record("a:1", 100, 50.0));
    slabs.push_back(record("a:1", 120, 60.0));  // the same process later: its peak grew
    slabs.push_back(record("a:2", 90, 55.0));
    slabs.push_back(record("b:7", 300, 58.0));  // another machine, alone there
    slabs.push_back(record("a:3", 500, 10.0));  // an earlier run's process
    CHECK(riner::slab_machine_peak_bytes(slabs, 40.0) == 300);  // b: 300 against a: 120 + 90
    slabs.push_back(record("a:4", 100, 70.0));
    CHECK(riner::slab_machine_peak_bytes(slabs, 40.0) == 310);  // a: 120 + 90 + 100
    // Nothing finished in this invocation (every slab done before): the largest record.
    CHECK(riner::slab_machine_peak_bytes(slabs, 100.0) == 500);
    // Records without a process (earlier riner versions) count only as the largest.
    nlohmann::json old = nlohmann::json::array();
    old.push_back({{"peak_host_bytes", 42}});
    CHECK(riner::slab_machine_peak_bytes(old, 0.0) == 42);
  }
}
