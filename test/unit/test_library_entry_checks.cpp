// What the library's entry points check of a Scan or Array a C++ caller built by hand (their
// fields are public): a shape that disagrees with the data, a made-up non-finite count, all-NaN
// or raw-intensity readings. Each is an InputError naming the problem, never a read past the
// data's end or an image of garbage.
#include <doctest/doctest.h>

#include <cmath>
#include <functional>
#include <limits>

#include "riner/centre.hpp"
#include "riner/concurrent_trainings.hpp"
#include "riner/destripe.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/io.hpp"
#include "riner/reconstructor.hpp"
#include "riner/scan.hpp"
#include "riner/slab_run.hpp"
#include "support/fixture.hpp"
#include "support/geometries.hpp"

namespace {

riner::Scan smooth_scan() {
  riner::Scan scan;
  scan.geometry = riner::test::small_parallel2d();
  const std::size_t views = scan.geometry.n_views(), columns = scan.geometry.n_u;
  scan.measurement = riner::Array({views, columns});
  for (std::size_t v = 0; v < views; ++v) {
    for (std::size_t c = 0; c < columns; ++c) {
      const double x = (static_cast<double>(c) - 47.0 - 10.0 * std::cos(0.05 * v)) / 12.0;
      scan.measurement(v, c) = static_cast<float>(std::exp(-x * x));
    }
  }
  return scan;
}

std::string error_of(const std::function<void()>& call) {
  try {
    call();
  } catch (const riner::InputError& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST_SUITE("library_entry_checks") {
  TEST_CASE("a scan whose data is shorter or longer than its shape is refused at every entry") {
    // 5000 values under a shape of 5700: the Reconstructor read past their end (valgrind), the
    // centre likewise; destripe said "a column's summary is not finite".
    for (const std::size_t length : {std::size_t{5000}, std::size_t{6000}}) {
      CAPTURE(length);
      riner::Scan scan = smooth_scan();
      scan.measurement.data.resize(length, 0.5f);
      const std::string expected = "holds 5700 values, its data " + std::to_string(length);
      riner::FbpOptions fbp_options;
      fbp_options.engine = riner::Engine::kReference;
      CHECK(error_of([&] { riner::check_scan(scan); }).find(expected) != std::string::npos);
      CHECK(error_of([&] { riner::fbp(scan, fbp_options); }).find(expected) != std::string::npos);
      CHECK(error_of([&] { riner::estimate_centre(scan); }).find(expected) != std::string::npos);
      riner::DestripeOptions destripe_options;
      destripe_options.engine = riner::Engine::kReference;
      CHECK(error_of([&] {
              riner::destripe(scan.measurement, scan.geometry, destripe_options);
            }).find(expected) != std::string::npos);
      riner::RinerConfig config;
      config.engine = riner::Engine::kReference;
      config.training.steps = 5;
      CHECK(error_of([&] { riner::Reconstructor r(scan, config); }).find(expected) !=
            std::string::npos);
    }
  }

  TEST_CASE("the non-finite count is the data's, not the caller's") {
    riner::Scan scan = smooth_scan();
    scan.non_finite = scan.measurement.size();  // says all NaN; none is
    CHECK_NOTHROW(riner::check_scan(scan));
    for (float& x : scan.measurement.data) x = NAN;
    scan.non_finite = 0;  // says none; all are
    CHECK(error_of([&] { riner::check_scan(scan); }).find("values are NaN or infinite") !=
          std::string::npos);
  }

  TEST_CASE("fbp refuses readings that are no line integrals, as the command line does") {
    riner::FbpOptions options;
    options.engine = riner::Engine::kReference;
    riner::Scan scan = smooth_scan();
    for (float& x : scan.measurement.data) x = NAN;  // was an image of zeros
    CHECK(error_of([&] { riner::fbp(scan, options); }).find("values are NaN or infinite") !=
          std::string::npos);
    scan = smooth_scan();
    for (float& x : scan.measurement.data) x = 5e5f * std::exp(-x);  // raw intensities
    CHECK(error_of([&] { riner::fbp(scan, options); }).find("look like raw intensities") !=
          std::string::npos);
    CHECK_NOTHROW(riner::fbp(smooth_scan(), options));
  }

  TEST_CASE("slab options a library caller sets are checked, as the CLI checks its own") {
    // A memory limit of 1 byte planned slabs of 261 MiB without a word; workers -3, processes
    // 0 and checkpoints every -5 s were taken; an output that is a file threw
    // std::filesystem::filesystem_error, not riner's.
    riner::test::TempDir dir;
    const riner::Geometry g = riner::test::small_parallel3d();
    riner::Array stack({g.n_views(), g.n_v, g.n_u}, 0.2f);
    riner::write_array(dir / "stack.npy", stack);
    riner::write_text(dir / "geometry.json", g.to_json());
    riner::RinerConfig config;
    config.engine = riner::Engine::kReference;
    const auto error_with = [&](const std::function<void(riner::SlabOptions&)>& set,
                                const std::filesystem::path& out) {
      riner::SlabOptions options;
      set(options);
      return error_of([&] {
        riner::SlabRun run(
            riner::ScanRows({(dir / "stack.npy").string(), "", "", "", std::nullopt, "", ""}),
            config, out, options);
      });
    };
    const std::filesystem::path out = dir / "run";
    CHECK(error_with([](riner::SlabOptions& o) { o.memory_limit = 1; }, out)
              .find("a memory limit of 1 bytes holds no slab") != std::string::npos);
    CHECK(
        error_with([](riner::SlabOptions& o) { o.workers = -3; }, out).find("workers must be 0") !=
        std::string::npos);
    CHECK(error_with([](riner::SlabOptions& o) { o.processes = 0; }, out)
              .find("processes 1 or more") != std::string::npos);
    CHECK(error_with([](riner::SlabOptions& o) { o.checkpoint_seconds = -5.0; }, out)
              .find("checkpoint seconds 0") != std::string::npos);
    riner::write_text(dir / "taken", "a file");
    CHECK(error_with([](riner::SlabOptions&) {}, dir / "taken")
              .find("is a file; a slabbed run writes into a folder") != std::string::npos);
    CHECK_THROWS_AS(riner::run_concurrently(2, 1, std::nullopt, {}), riner::Error);
  }

  TEST_CASE("a range along the first axis past its end is refused, not wrapped") {
    const riner::Array a({4, 4}, 1.0f);
    CHECK_THROWS_AS(riner::first_axis_range(a, 2, std::numeric_limits<std::size_t>::max()),
                    riner::InputError);
    CHECK(riner::first_axis_range(a, 1, 3).shape == std::vector<std::size_t>{3, 4});
  }
}
