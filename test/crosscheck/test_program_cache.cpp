// The on-disk program cache: a second context loads the binary instead of compiling; corrupt
// entries are discarded and rebuilt; concurrent builders never see a partial entry.
#include <doctest/doctest.h>

#include <cstdlib>
#include <thread>

#include "cl/context.hpp"
#include "cl/device_access.hpp"
#include "cl/program_builder.hpp"
#include "ops/vector_ops.hpp"
#include "support/fixture.hpp"

namespace {

// Points the cache at a scratch directory for the life of the object, by default on every
// platform (PoCL, which caches its own kernels, is not served otherwise).
struct ScratchCache {
  riner::test::TempDir dir;
  std::string previous;
  explicit ScratchCache(bool every_platform = true) {
    if (const char* p = std::getenv("RINER_CACHE_DIR")) previous = p;
    setenv("RINER_CACHE_DIR", dir.path().c_str(), 1);
    riner::cl::serve_every_platform_for_tests(every_platform);
  }
  ~ScratchCache() {
    riner::cl::serve_every_platform_for_tests(false);
    if (previous.empty()) {
      unsetenv("RINER_CACHE_DIR");
    } else {
      setenv("RINER_CACHE_DIR", previous.c_str(), 1);
    }
  }
  std::vector<std::filesystem::path> entries() const {
    std::vector<std::filesystem::path> out;
    for (const auto& e : std::filesystem::directory_iterator(dir.path())) out.push_back(e.path());
    return out;
  }
};

riner::cl::ProgramCacheStats build_in_fresh_context(const std::string& options = "") {
  riner::Device device = riner::Device::open();
  riner::cl::context_of(device).program({"common", "vector_ops"}, options);
  return riner::cl::context_of(device).program_cache_stats();
}

}  // namespace

TEST_SUITE("program_cache") {
  TEST_CASE("PoCL's programs are left to PoCL's own cache") {
    ScratchCache cache(false);
    riner::Device device = riner::Device::open();
    const bool pocl = riner::cl::context_of(device).info().platform.find(
                          "Portable Computing Language") != std::string::npos;
    riner::cl::context_of(device).program({"common", "vector_ops"});
    CHECK(cache.entries().empty() == pocl);
    CHECK(riner::cl::disk_cache_serves("NVIDIA CUDA"));
    CHECK(!riner::cl::disk_cache_serves("Portable Computing Language"));
  }

  TEST_CASE("second context hits the disk cache; options are part of the key") {
    ScratchCache cache;
    CHECK(build_in_fresh_context().source_builds == 1);
    REQUIRE(cache.entries().size() == 1);
    const auto second = build_in_fresh_context();
    CHECK(second.disk_hits == 1);
    CHECK(second.source_builds == 0);
    CHECK(build_in_fresh_context("-DUNUSED_OPTION=1").source_builds == 1);
    CHECK(cache.entries().size() == 2);
  }

  TEST_CASE("the same context serves repeats from memory") {
    ScratchCache cache;
    riner::Device device = riner::Device::open();
    riner::cl::context_of(device).program({"common", "vector_ops"});
    riner::cl::context_of(device).program({"common", "vector_ops"});
    const auto stats = riner::cl::context_of(device).program_cache_stats();
    CHECK(stats.source_builds == 1);
    CHECK(stats.memory_hits == 1);
  }

  TEST_CASE("corrupt or truncated entries are discarded with a warning and rebuilt") {
    ScratchCache cache;
    build_in_fresh_context();
    REQUIRE(cache.entries().size() == 1);
    const auto entry = cache.entries()[0];
    std::string bytes = riner::test::read_bytes(entry);
    for (int variant = 0; variant < 3; ++variant) {
      std::string bad = bytes;
      if (variant == 0) bad = bytes.substr(0, bytes.size() / 2);  // truncated
      if (variant == 1) bad[bad.size() - 10] ^= 0x40;             // flipped binary byte
      if (variant == 2) bad = "not a cache entry";                // garbage
      riner::test::write_bytes(entry, bad);
      riner::test::take_warnings();
      const auto stats = build_in_fresh_context();
      CHECK(stats.source_builds == 1);
      const auto warnings = riner::test::take_warnings();
      REQUIRE(warnings.size() == 1);
      CHECK(warnings[0].find("discarded a corrupt program cache entry") != std::string::npos);
      // The rebuilt entry is whole again and loads.
      CHECK(build_in_fresh_context().disk_hits == 1);
    }
  }

  TEST_CASE("concurrent builders share the cache safely") {
    ScratchCache cache;
    std::vector<std::thread> threads;
    std::atomic<int> failures{0};
    for (int t = 0; t < 4; ++t) {
      threads.emplace_back([&] {
        try {
          riner::Device device = riner::Device::open();
          riner::ops::VectorOps ops(riner::cl::context_of(device));
        } catch (...) {
          ++failures;
        }
      });
    }
    for (auto& t : threads) t.join();
    CHECK(failures == 0);
    CHECK(cache.entries().size() == 1);  // no temporary files left behind
    CHECK(build_in_fresh_context().disk_hits == 1);
  }

  TEST_CASE("RINER_CACHE_DIR=off disables the disk cache") {
    ScratchCache cache;
    setenv("RINER_CACHE_DIR", "off", 1);
    CHECK_FALSE(riner::cl::binary_cache_dir().has_value());
    CHECK(build_in_fresh_context().source_builds == 1);
    CHECK(build_in_fresh_context().source_builds == 1);
  }
}
