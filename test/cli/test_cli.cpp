// The riner executable end to end: exit codes, one-line errors, outputs that read back.
#include <doctest/doctest.h>
#include <unistd.h>

#include <sys/wait.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "cli/cli_run.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/quality.hpp"
#include "support/fixture.hpp"

namespace {

using riner::test::Run;
using riner::test::riner_cli;
using riner::test::simulate_small_parallel3d;

void expect_error(const Run& run, int code, const std::string& message) {
  CAPTURE(run.err);
  CHECK(run.code == code);
  CHECK(run.err.find("riner: error: " + message) != std::string::npos);
  // One line.
  CHECK(std::count(run.err.begin(), run.err.end(), '\n') == 1);
}

// A small cone-beam geometry (36 views, 30 x 20 detector, 10 x 24 x 24 volume) as dir/g3.json;
// returns its path.
std::string write_small_cone3d_geometry(const riner::test::TempDir& dir) {
  riner::test::write_bytes(dir / "g3.json", R"({"type": "cone3d",
      "detector": {"count": [30, 20], "pitch_mm": [2.0, 2.0]}, "source_origin_mm": 300,
      "origin_detector_mm": 300, "angles": {"count": 36, "range_rad": 6.283185307179586},
      "volume": {"shape": [10, 24, 24], "voxel_mm": 1.0}})");
  return (dir / "g3.json").string();
}

}  // namespace

TEST_SUITE("cli") {
  TEST_CASE("usage errors exit 2 with a pointer to --help") {
    riner::test::TempDir dir;
    CHECK(riner_cli("--version", dir).code == 0);
    CHECK(riner_cli("", dir).code == 2);
    expect_error(riner_cli("frobnicate", dir), 2,
                 "unknown command 'frobnicate' (see riner --help)");
    expect_error(riner_cli("info", dir), 2, "missing FILE (see riner info --help)");
    expect_error(riner_cli("simulate --seed x --out " + dir.path().string(), dir), 2,
                 "--seed expects an integer, got 'x'");
    expect_error(riner_cli("fbp a.npy --out b.nii --filter box", dir), 2, "a.npy: no such file");
    const Run help = riner_cli("fbp --help", dir);
    CHECK(help.code == 0);
    CHECK(help.out.find("usage: riner fbp SCAN") == 0);
  }

  TEST_CASE("the guide lists the commands of riner --help, in its order") {
    riner::test::TempDir dir;
    const Run help = riner_cli("--help", dir);
    REQUIRE(help.code == 0);
    std::vector<std::string> listed;  // "  name   summary" lines under "commands:"
    std::istringstream lines(help.out.substr(help.out.find("commands:\n") + 10));
    for (std::string line; std::getline(lines, line) && line.rfind("  ", 0) == 0;) {
      listed.push_back(line.substr(2, line.find(' ', 2) - 2));
    }
    REQUIRE(listed.size() >= 10);
    const std::string guide =
        riner::test::read_bytes(std::string(RINER_SOURCE_DIR) + "/docs/guide/command-line.md");
    std::size_t at = 0;
    for (const std::string& name : listed) {
      const std::size_t row = guide.find("| `riner " + name, at);
      CHECK_MESSAGE(row != std::string::npos,
                    (std::string("docs/guide/command-line.md: no row for `riner ") + name +
                     "` after the previous"));
      if (row != std::string::npos) at = row;
    }
  }

  TEST_CASE("simulate -> fbp -> compare, with JSON summaries") {
    riner::test::TempDir dir;
    const std::string out = (dir / "sim").string();
    Run sim = riner_cli("simulate --out " + out + " --seed 5 --json", dir);
    REQUIRE(sim.code == 0);
    const auto summary = nlohmann::json::parse(sim.out);
    CHECK(summary["dead_elements"].size() == 2);
    CHECK(summary["non_finite_measurements"] == 720);
    for (const char* f : {"sino.npy", "sino_clean.npy", "alpha.npy", "ground_truth.nii",
                          "geometry.json", "simulation.json", "sino.png", "ground_truth.png"}) {
      CHECK(std::filesystem::exists(std::filesystem::path(out) / f));
    }
    REQUIRE(riner_cli("fbp " + out + "/sino_clean.npy --geometry " + out + "/geometry.json --out " +
                          out + "/fbp.nii --png --quiet",
                      dir)
                .code == 0);
    CHECK(std::filesystem::exists(std::filesystem::path(out) / "fbp.png"));
    const Run compare =
        riner_cli("compare " + out + "/fbp.nii " + out + "/ground_truth.nii --json", dir);
    REQUIRE(compare.code == 0);
    CHECK(nlohmann::json::parse(compare.out)["psnr_db"].get<double>() > 30.0);
    // Five spikes of 1e5 among readings up to about 6 (under the absolute 1e6): before, FBP
    // -46 dB unsaid and the centre 11.9 px off; now repaired as the other views tell.
    riner::Array spiked = riner::read_array(out + "/sino_clean.npy").array;
    for (std::size_t k : {1234u, 40000u, 77777u, 123456u, 150001u}) spiked.data[k] = 1e5f;
    riner::write_array(dir / "spiked.npy", spiked);
    REQUIRE(riner_cli("fbp " + (dir / "spiked.npy").string() + " --geometry " + out +
                          "/geometry.json --out " + out + "/spiked.nii --quiet",
                      dir)
                .code == 0);
    const Run spiked_compare =
        riner_cli("compare " + out + "/spiked.nii " + out + "/ground_truth.nii --json", dir);
    REQUIRE(spiked_compare.code == 0);
    CHECK(nlohmann::json::parse(spiked_compare.out)["psnr_db"].get<double>() >
          nlohmann::json::parse(compare.out)["psnr_db"].get<double>() - 0.1);
    const Run centre = riner_cli(
        "center " + (dir / "spiked.npy").string() + " --geometry " + out + "/geometry.json --json",
        dir);
    REQUIRE(centre.code == 0);
    CHECK(std::fabs(nlohmann::json::parse(centre.out)["offset_px"].get<double>()) < 0.5);
    // Same seed, same scan, bit for bit.
    REQUIRE(riner_cli("simulate --quiet --seed 5 --out " + out + "2", dir).code == 0);
    CHECK(riner::test::read_bytes(out + "/sino.npy") ==
          riner::test::read_bytes(out + "2/sino.npy"));
  }

  TEST_CASE("readings far below zero are said: the wrong sign, or another exposure's flat") {
    riner::test::TempDir dir;
    const std::string sim = riner::test::simulate_small_parallel2d(dir, 2);
    const std::string note = "more light than the flat field gives, far beyond noise";
    const auto fbp_of = [&](const std::filesystem::path& sino) {
      const Run run = riner_cli("fbp " + sino.string() + " --geometry " + sim +
                                    "/geometry.json --out " + (dir / "f.npy").string(),
                                dir);
      REQUIRE(run.code == 0);
      return run.out + run.err;
    };
    CHECK(fbp_of(sim + "/sino.npy").find(note) == std::string::npos);
    riner::Array flipped = riner::read_array(sim + "/sino.npy").array;
    for (std::size_t v = 0; v < 90; ++v) {
      for (std::size_t u = 30; u < 40; ++u) flipped.data[v * 70 + u] *= -1.0f;
    }
    riner::write_array(dir / "flipped.npy", flipped);
    CHECK(fbp_of(dir / "flipped.npy").find(note) != std::string::npos);
  }

  TEST_CASE("metal that stops the beam is trained as a bound: the disc is dense, not air") {
    // A water disc (0.02/mm) with a metal disc (3/mm, 9 px across) off the axis: its central
    // rays keep no photon of 10^7 (+inf). Before, those readings counted as 0 (air): the disc
    // read -0.12/mm. On the axis, its central elements read nothing in any view: they were
    // taken for dead, and the disc read 1.04, its middle -2.4 (now 2.70).
    for (const auto& [mx0, my0] : {std::pair{42.0, 30.0}, std::pair{31.5, 31.5}}) {
      CAPTURE(mx0);
      riner::test::TempDir dir;
      riner::Array phantom({64, 64}, 0.0f);
      std::size_t metal = 0;
      for (std::size_t y = 0; y < 64; ++y) {
        for (std::size_t x = 0; x < 64; ++x) {
          const double dx = x - 31.5, dy = y - 31.5, mx = x - mx0, my = y - my0;
          if (dx * dx + dy * dy < 28.0 * 28.0) phantom(y, x) = 0.02f;
          if (mx * mx + my * my < 4.5 * 4.5) phantom(y, x) = 3.0f, ++metal;
        }
      }
      riner::write_array(dir / "metal.npy", phantom);
      const std::string sim =
          riner::test::simulate_geometry(dir, "g2.json", R"({"type": "parallel2d",
      "detector": {"count": 70, "pitch_mm": 1.0},
      "angles": {"count": 90, "range_rad": 3.141592653589793},
      "volume": {"shape": [64, 64], "voxel_mm": 1.0}})",
                                         "--seed 3 --phantom " + (dir / "metal.npy").string());
      const nlohmann::json simulation =
          nlohmann::json::parse(riner::test::read_bytes(sim + "/simulation.json"));
      REQUIRE(simulation["non_finite_measurements"].get<std::size_t>() > 200);
      const Run run =
          riner_cli("reconstruct " + sim + "/sino.npy --steps 2000 --format npy --out " +
                        (dir / "rec").string(),
                    dir);
      REQUIRE(run.code == 0);
      CHECK(run.out.find("are a beam the object stopped") != std::string::npos);
      const nlohmann::json summary =
          nlohmann::json::parse(riner::test::read_bytes(dir / "rec" / "summary.json"));
      CHECK(summary["starved_readings"].get<std::size_t>() > 100);
      const riner::Array image = riner::read_array(dir / "rec" / "image.npy").array;
      double disc = 0.0;
      for (std::size_t i = 0; i < image.size(); ++i)
        disc += phantom.data[i] > 1.0f ? image.data[i] : 0.0;
      disc /= static_cast<double>(metal);
      CAPTURE(disc);
      CHECK(disc > 2.0);  // 2.76 at 2000 steps (the truth 3.0; before, -0.12: air; 2.07 while the
                          // simulation's dead element 33, across its trace, pulled it down)
      CHECK(disc < 4.5);
      // The simulation's dead elements and no others: the metal's elements are live (on the
      // axis, a dead element in its shadow, elements 30-39, is no different from them).
      const auto dead = summary["dead_elements"].get<std::vector<int>>();
      for (const int e : simulation["dead_elements"].get<std::vector<int>>()) {
        const bool shadowed = mx0 < 40.0 && e >= 30 && e <= 39;
        CHECK((std::find(dead.begin(), dead.end(), e) != dead.end()) != shadowed);
      }
      CHECK(dead.size() <= simulation["dead_elements"].size());
      // FBP reads them as the largest finite reading, so the metal shows, and says so; filled
      // from their neighbours (before, FBP's only way) it reads lighter still.
      const Run fbp =
          riner_cli("fbp " + sim + "/sino.npy --json --out " + (dir / "fbp.npy").string(), dir);
      REQUIRE(fbp.code == 0);
      const nlohmann::json fbp_summary = nlohmann::json::parse(fbp.out);
      CHECK(fbp_summary["stopped_beam_readings"] == summary["starved_readings"]);
      CHECK(fbp_summary["stopped_beam_floor"].get<double>() ==
            doctest::Approx(summary["starved_floor"].get<double>()));
      CHECK(fbp.err.find("look like a beam the object stopped") != std::string::npos);
      const Run filled = riner_cli("fbp " + sim + "/sino.npy --fill-stopped-beam --quiet --out " +
                                       (dir / "filled.npy").string(),
                                   dir);
      REQUIRE(filled.code == 0);
      const auto metal_mean = [&](const riner::Array& a) {
        double sum = 0.0;
        for (std::size_t i = 0; i < a.size(); ++i) sum += phantom.data[i] > 1.0f ? a.data[i] : 0.0;
        return sum / static_cast<double>(metal);
      };
      const double at_floor = metal_mean(riner::read_array(dir / "fbp.npy").array);
      const double interpolated = metal_mean(riner::read_array(dir / "filled.npy").array);
      CAPTURE(at_floor);
      CAPTURE(interpolated);
      CHECK(at_floor > 1.5);                 // 1.73 off the axis, 1.86 on it (the truth 3.0)
      CHECK(at_floor > 1.5 * interpolated);  // 1.08 and 1.04
      // Through the stripe filter too (it fills every invalid reading; before, 1.14).
      const Run destriped = riner_cli("fbp " + sim + "/sino.npy --destripe all --json --out " +
                                          (dir / "destriped.npy").string(),
                                      dir);
      REQUIRE(destriped.code == 0);
      CHECK(nlohmann::json::parse(destriped.out)["stopped_beam_readings"] ==
            summary["starved_readings"]);
      const double through_filter = metal_mean(riner::read_array(dir / "destriped.npy").array);
      CAPTURE(through_filter);
      CHECK(through_filter > 1.5);
      // A lost tile, 16 elements in two views away from the metal, is no metal's edge: FBP
      // interpolates it (at the floor it drew a streak across the image).
      riner::Array sino = riner::read_array(sim + "/sino.npy").array;
      for (std::size_t v = 60; v < 62; ++v) {
        for (std::size_t e = 2; e < 18; ++e) sino(v, e) = INFINITY;
      }
      riner::write_array(dir / "tile.npy", sino);
      REQUIRE(riner_cli("fbp " + (dir / "tile.npy").string() + " --geometry " + sim +
                            "/geometry.json --quiet --out " + (dir / "tile_fbp.npy").string(),
                        dir)
                  .code == 0);
      const riner::Array with_tile = riner::read_array(dir / "tile_fbp.npy").array;
      const riner::Array without = riner::read_array(dir / "fbp.npy").array;
      double tile_rms = 0.0, outside = 0.0;
      for (std::size_t i = 0; i < without.size(); ++i) {
        if (phantom.data[i] > 1.0f) continue;
        const double d = with_tile.data[i] - without.data[i];
        tile_rms += d * d, outside += 1.0;
      }
      tile_rms = std::sqrt(tile_rms / outside);
      CAPTURE(tile_rms);
      CHECK(tile_rms < 0.005);
    }
  }

  TEST_CASE("a stack's FBP shows its metal the same in any slabs") {
    // A water cylinder with a 3/mm rod through its upper half: the rod stops the beam (+inf),
    // FBP reads those readings as their detector row's largest finite reading. A slab's own
    // largest (or its own classification) would change with the cut; a row's does not.
    riner::test::TempDir dir;
    riner::Array phantom({16, 32, 32}, 0.0f);
    for (std::size_t z = 0; z < 16; ++z) {
      for (std::size_t y = 0; y < 32; ++y) {
        for (std::size_t x = 0; x < 32; ++x) {
          const double dx = x - 15.5, dy = y - 15.5, mx = x - 20.0, my = y - 14.0;
          if (dx * dx + dy * dy < 14.0 * 14.0) phantom(z, y, x) = 0.02f;
          if (z < 8 && mx * mx + my * my < 3.0 * 3.0) phantom(z, y, x) = 3.0f;
        }
      }
    }
    riner::write_array(dir / "rod.npy", phantom);
    const std::string sim =
        riner::test::simulate_geometry(dir, "g3.json", R"({"type": "parallel3d",
      "detector": {"count": [36, 16], "pitch_mm": [1.0, 1.0]},
      "angles": {"count": 60, "range_rad": 3.141592653589793},
      "volume": {"shape": [16, 32, 32], "voxel_mm": 1.0}})",
                                       "--seed 4 --phantom " + (dir / "rod.npy").string());
    // Rows 4-7 a stop less light (their largest finite reading 17.1, the others' 16.1): a slab
    // of rows 3-5 holds both.
    riner::Array sino = riner::read_array(sim + "/sino.npy").array;
    for (std::size_t v = 0; v < 60; ++v) {
      for (std::size_t i = 4 * 36; i < 8 * 36; ++i) sino.data[v * 16 * 36 + i] += 1.0f;
    }
    riner::write_array(sim + "/rows.npy", sino);
    std::vector<nlohmann::json> summaries;
    for (const char* slices : {"16", "4", "3"}) {
      const Run run =
          riner_cli("fbp " + sim + "/rows.npy --slab-slices " + slices + " --json --out " +
                        (dir / (std::string("v") + slices + ".npy")).string(),
                    dir);
      REQUIRE(run.code == 0);
      summaries.push_back(nlohmann::json::parse(run.out));
    }
    const riner::Array whole = riner::read_array(dir / "v16.npy").array;
    for (const char* slices : {"4", "3"}) {
      const riner::Array cut = riner::read_array(dir / (std::string("v") + slices + ".npy")).array;
      // A slab's backprojection may round differently (5e-7, with the metal interpolated too);
      // a slab's own floor moved the rod's voxels by tenths.
      float largest = 0.0f;
      for (std::size_t i = 0; i < whole.size(); ++i) {
        largest = std::max(largest, std::fabs(cut.data[i] - whole.data[i]));
      }
      const std::string slab_slices = slices;
      CAPTURE(slab_slices);
      CHECK(largest < 1e-5f);
    }
    CHECK(summaries[0]["stopped_beam_readings"].get<std::size_t>() > 100);
    CHECK(summaries[1]["stopped_beam_readings"] == summaries[0]["stopped_beam_readings"]);
    CHECK(summaries[2]["stopped_beam_readings"] == summaries[0]["stopped_beam_readings"]);
    // The rod shows: its voxels read far above the water's 0.02.
    double rod = 0.0, n = 0.0;
    for (std::size_t i = 0; i < whole.size(); ++i) {
      if (phantom.data[i] > 1.0f) rod += whole.data[i], n += 1.0;
    }
    CAPTURE(rod / n);
    CHECK(rod / n > 1.0);
  }

  TEST_CASE("metal in raw projections whose dark frames are noisy: no element taken for dead") {
    // The metal scene above (off the axis), as a detector counts it: 10^4 counts of beam,
    // a dark of 100 with a noise of 5 counts, 10 flat and 10 dark frames. Behind the metal the
    // light is within the dark's noise: some readings fall below the dark (+inf), others a few
    // counts above it (-ln reads 6-9), which broke the metal's trace into short runs. Before,
    // 21 live elements across the trace were flagged dead (23 with the 2 dead) and 226 readings
    // kept as bounds.
    riner::test::TempDir dir;
    riner::Array phantom({64, 64}, 0.0f);
    for (std::size_t y = 0; y < 64; ++y) {
      for (std::size_t x = 0; x < 64; ++x) {
        const double dx = x - 31.5, dy = y - 31.5, mx = x - 42.0, my = y - 30.0;
        if (dx * dx + dy * dy < 28.0 * 28.0) phantom(y, x) = 0.02f;
        if (mx * mx + my * my < 4.5 * 4.5) phantom(y, x) = 3.0f;
      }
    }
    riner::write_array(dir / "metal.npy", phantom);
    const std::string sim = riner::test::simulate_geometry(
        dir, "g2.json", R"({"type": "parallel2d", "detector": {"count": 70, "pitch_mm": 1.0},
      "angles": {"count": 90, "range_rad": 3.141592653589793},
      "volume": {"shape": [64, 64], "voxel_mm": 1.0}})",
        "--seed 3 --photons 0 --phantom " + (dir / "metal.npy").string());
    const riner::Array rho = riner::read_array(sim + "/sino_clean.npy").array;
    const riner::Array alpha = riner::read_array(sim + "/alpha.npy").array;
    const std::size_t views = 90, elements = 70;
    std::mt19937 random(5);
    std::normal_distribution<double> dark_noise(0.0, 5.0);
    auto count = [&](double mean) {
      return static_cast<float>(
          std::round(std::poisson_distribution<int>(mean)(random) + 100.0 + dark_noise(random)));
    };
    riner::Array flats({10, 1, elements}), darks({10, 1, elements}), raw({views, 1, elements});
    for (std::size_t f = 0; f < 10; ++f) {
      for (std::size_t e = 0; e < elements; ++e) {
        flats.data[f * elements + e] = count(1e4 * alpha.data[e]);
        darks.data[f * elements + e] = count(0.0);
      }
    }
    for (std::size_t i = 0; i < raw.size(); ++i) {
      raw.data[i] = count(1e4 * alpha.data[i % elements] * std::exp(-rho.data[i]));
    }
    riner::write_array(dir / "raw.npy", raw);
    riner::write_array(dir / "flats.npy", flats);
    riner::write_array(dir / "darks.npy", darks);
    const std::string at = dir.path().string() + "/";
    const Run run = riner_cli("reconstruct " + at + "raw.npy --flat " + at + "flats.npy --dark " +
                                  at + "darks.npy --geometry " + at +
                                  "g2.json --row 0 --steps 2000 --format npy --out " + at + "rec",
                              dir);
    CAPTURE(run.err);
    REQUIRE(run.code == 0);
    CHECK(run.out.find("no more light than 3 times the dark's noise") != std::string::npos);
    const nlohmann::json simulation =
        nlohmann::json::parse(riner::test::read_bytes(sim + "/simulation.json"));
    const nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(dir / "rec" / "summary.json"));
    CHECK(summary["starved_readings"].get<std::size_t>() > 500);
    const auto dead = summary["dead_elements"].get<std::vector<int>>();
    CAPTURE(summary["dead_elements"].dump());
    CHECK(dead.size() <= simulation["dead_elements"].size() + 1);  // 2 (before, 24)
    const riner::Array image = riner::read_array(dir / "rec" / "image.npy").array;
    double metal = 0.0, n = 0.0;
    for (std::size_t i = 0; i < image.size(); ++i) {
      if (phantom.data[i] > 1.0f) metal += image.data[i], n += 1.0;
    }
    // Past its rim no light says how dense the metal is: its middle, read only by bounds its rim
    // meets, reads about 0 (the mean 0.90 at 2000 steps), and the console says those voxels'
    // values are unknown.
    CAPTURE(metal / n);
    CHECK(metal / n > 0.5);
    CHECK(summary["stopped_hull"]["voxels"].get<std::size_t>() > 30);
    CHECK(run.out.find("lie in the full shadow of what stopped the beam") != std::string::npos);
  }

  TEST_CASE("metal across dead elements, a module failing beside its trace: no streaks") {
    // A 128 x 128 body with a 3/mm metal disc 17 px off the axis, 160 elements x 180 views over
    // 180 degrees. (1) Three adjacent elements dead in every view cross the metal's trace: their
    // readings, counted as 0 from beta0 = 1, pulled the field down along rays that cross the
    // metal, held only from below by its bounds: streaks, the error outside the metal 0.054/mm
    // (0.0104 without the dead elements). (2) Eight elements dark from view 100 on, one of them
    // darkened by the trace just before: it alone was kept as bounds, 0.028/mm.
    riner::test::TempDir dir;
    riner::Array phantom({128, 128}, 0.0f);
    const auto inside = [](double x, double y, double cx, double cy, double rx, double ry) {
      return (x - cx) * (x - cx) / (rx * rx) + (y - cy) * (y - cy) / (ry * ry) < 1.0;
    };
    for (std::size_t j = 0; j < 128; ++j) {
      for (std::size_t i = 0; i < 128; ++i) {
        const double x = i + 0.5 - 64.0, y = j + 0.5 - 64.0;
        float mu = inside(x, y, 0, 0, 56, 48) ? 0.02f : 0.0f;
        if (inside(x, y, -20, 10, 10, 14)) mu = 0.03f;
        if (inside(x, y, 5, -25, 6, 6)) mu = 0.035f;
        if (inside(x, y, -10, -5, 3, 3)) mu = 0.01f;
        if (inside(x, y, 16.5, -3.5, 4.5, 4.5)) mu = 3.0f;
        phantom(j, i) = mu;
      }
    }
    riner::write_array(dir / "metal.npy", phantom);
    const std::string sim = riner::test::simulate_geometry(
        dir, "g.json", R"({"type": "parallel2d",
      "detector": {"count": 160, "pitch_mm": 1.0},
      "angles": {"count": 180, "range_rad": 3.141592653589793},
      "volume": {"shape": [128, 128], "voxel_mm": 1.0}})",
        "--seed 1 --dead 0 --phantom " + (dir / "metal.npy").string());
    const riner::Array sino = riner::read_array(sim + "/sino.npy").array;
    const auto error_outside = [&](const std::string& name, riner::Array scan) {
      riner::write_array(dir / (name + ".npy"), scan);
      const Run run = riner_cli("reconstruct " + (dir / (name + ".npy")).string() + " --geometry " +
                                    (dir / "g.json").string() +
                                    " --steps 3000 --format npy --out " + (dir / name).string(),
                                dir);
      REQUIRE(run.code == 0);
      const riner::Array image = riner::read_array(dir / name / "image.npy").array;
      double sum = 0.0, disc = 0.0;
      std::size_t n = 0, metal = 0;
      for (std::size_t j = 0; j < 128; ++j) {
        for (std::size_t i = 0; i < 128; ++i) {
          const double x = i + 0.5 - 64.0, y = j + 0.5 - 64.0;
          const double e = image(j, i) - phantom(j, i);
          if (phantom(j, i) > 1.0f) disc += image(j, i), ++metal;
          if (inside(x, y, 16.5, -3.5, 7.0, 7.0) || !inside(x, y, 0, 0, 62, 62)) continue;
          sum += e * e, ++n;
        }
      }
      CHECK(disc / static_cast<double>(metal) > 2.0);  // 2.77 and 2.95 here (truth 3)
      return std::sqrt(sum / static_cast<double>(n));
    };
    riner::Array dead = sino, module = sino;
    for (std::size_t v = 0; v < 180; ++v) {
      for (std::size_t u = 88; u < 91; ++u) dead.data[v * 160 + u] = INFINITY;
      for (std::size_t u = 84; u < 92 && v >= 100; ++u) module.data[v * 160 + u] = INFINITY;
    }
    CHECK(error_outside("dead", dead) < 0.02);      // 0.0118 here; before, 0.054 (the disc 1.90)
    CHECK(error_outside("module", module) < 0.02);  // 0.0108 here; before, 0.028
  }

  TEST_CASE("a grid far beyond the detector's rays, an object beyond its ends: both said") {
    // An audit's grid 8 times too wide drew no word; its outer part is seen by no ray.
    riner::test::TempDir dir;
    const std::string sim = riner::test::simulate_small_parallel2d(dir, 2);
    const auto fbp_with_voxel = [&](double voxel) {
      char json[300];
      std::snprintf(json, sizeof(json), R"({"type": "parallel2d",
          "detector": {"count": 70, "pitch_mm": 1.0},
          "angles": {"count": 90, "range_rad": 3.141592653589793},
          "volume": {"shape": [64, 64], "voxel_mm": %g}})",
                    voxel);
      riner::test::write_bytes(dir / "g.json", json);
      const Run run = riner_cli("fbp " + sim + "/sino.npy --geometry " + (dir / "g.json").string() +
                                    " --out " + (dir / "f.npy").string(),
                                dir);
      REQUIRE(run.code == 0);
      return run.out + run.err;
    };
    const std::string note = "times as far from the axis as the detector's rays";
    CHECK(fbp_with_voxel(1.0).find(note) == std::string::npos);
    CHECK(fbp_with_voxel(2.0).find(note) == std::string::npos);  // 1.8 times: no word
    const std::string wide = fbp_with_voxel(8.0);
    CAPTURE(wide);
    CHECK(wide.find("the grid reaches 7.31 " + note) != std::string::npos);
    // And the other way: an object wider than the field of view (40 columns under a phantom
    // 61 wide) is said, where FBP cups.
    CHECK(fbp_with_voxel(1.0).find("reaches the detector's ends") == std::string::npos);
    riner::test::write_bytes(dir / "narrow.json", R"({"type": "parallel2d",
        "detector": {"count": 40, "pitch_mm": 1.0},
        "angles": {"count": 90, "range_rad": 3.141592653589793},
        "volume": {"shape": [64, 64], "voxel_mm": 1.0}})");
    REQUIRE(riner_cli("simulate --quiet --geometry " + (dir / "narrow.json").string() + " --out " +
                          (dir / "cut").string(),
                      dir)
                .code == 0);
    const Run cut = riner_cli(
        "fbp " + (dir / "cut" / "sino.npy").string() + " --out " + (dir / "cut.npy").string(), dir);
    REQUIRE(cut.code == 0);
    CHECK((cut.out + cut.err).find("note: the object reaches the detector's ends") !=
          std::string::npos);
  }

  TEST_CASE("a scan whose readings are all one value is refused, saying why") {
    riner::test::TempDir dir;
    const std::string sim = riner::test::simulate_small_parallel2d(dir, 2);
    for (const auto& [value, why] :
         {std::pair{0.0f, "every reading is 0: the rays crossed nothing"},
          std::pair{1.0f, "every reading is 1: no object reads alike"}}) {
      riner::Array flat({90, 70}, value);
      flat.data[5] = NAN;  // a dead reading does not make a scan
      riner::write_array(dir / "flat.npy", flat);
      for (const char* command : {"reconstruct", "fbp"}) {
        CAPTURE(command);
        const Run run =
            riner_cli(std::string(command) + " " + (dir / "flat.npy").string() + " --geometry " +
                          sim + "/geometry.json --out " + (dir / "out.npy").string(),
                      dir);
        CHECK(run.code == 2);
        CHECK(run.err.find(why) != std::string::npos);
      }
    }
  }

  TEST_CASE("a scan in another length unit trains to the same image in that unit") {
    // Before (the audit): the image depended on the numbers' scale, FBP's did not. Micrometre
    // pixels given in mm (mu x 1000) lost 6.7 dB and flagged ten live elements dead; readings
    // x 0.001 trained to speckle (16.4 dB against 30.8). The field now learns mu times a power
    // of two: voxels of 2^-10 and 2^-12 mm train the same field, to the bit.
    riner::test::TempDir dir;
    const std::string sim = riner::test::simulate_small_parallel2d(dir, 3);
    const auto in_unit = [&](const std::string& name, double mm) {
      char json[400];
      std::snprintf(json, sizeof(json), R"({"type": "parallel2d",
          "detector": {"count": 70, "pitch_mm": %.17g},
          "angles": {"count": 90, "range_rad": 3.141592653589793},
          "volume": {"shape": [64, 64], "voxel_mm": %.17g}})",
                    mm, mm);
      riner::test::write_bytes(dir / (name + ".json"), json);
      const Run run = riner_cli(
          "reconstruct " + sim + "/sino.npy --geometry " + (dir / (name + ".json")).string() +
              " --steps 2000 --quiet --format npy --out " + (dir / name).string(),
          dir);
      REQUIRE(run.code == 0);
      return std::pair{riner::read_array(dir / name / "image.npy").array,
                       nlohmann::json::parse(riner::test::read_bytes(dir / name / "summary.json"))};
    };
    const auto [mm, mm_summary] = in_unit("mm", 1.0);
    const auto [fine, fine_summary] = in_unit("fine", std::ldexp(1.0, -10));
    const auto [finer, finer_summary] = in_unit("finer", std::ldexp(1.0, -12));
    CHECK(mm_summary["field_per_mu"] == 1.0);
    CHECK(fine_summary["field_per_mu"].get<double>() ==
          4.0 * finer_summary["field_per_mu"].get<double>());
    riner::Array scaled = finer;
    for (float& v : scaled.data) v *= 0.25f;
    CHECK(scaled.data == fine.data);
    // Against the truth in each unit: as good as in mm.
    const riner::Array truth = riner::read_array(sim + "/ground_truth.nii").array;
    riner::Array in_mm = fine;
    for (float& v : in_mm.data) v = std::ldexp(v, -10);
    const double psnr_mm = riner::psnr(mm, truth), psnr_fine = riner::psnr(in_mm, truth);
    CAPTURE(psnr_mm);
    CAPTURE(psnr_fine);
    CHECK(psnr_fine > psnr_mm - 1.0);
    CHECK(fine_summary["dead_elements"] == mm_summary["dead_elements"]);
  }

  TEST_CASE(
      "views that miss part of the circle are warned by reconstruct as by fbp; two turns not") {
    // Before: reconstruct said nothing of a 0.5-degree arc, and fbp took a 720-degree scan for
    // one missing part of the circle (its views paired up in the weights).
    riner::test::TempDir dir;
    const std::string sim = riner::test::simulate_small_parallel2d(dir, 2);
    const auto with_range = [&](const std::string& name, double range) {
      riner::test::write_bytes(dir / name, R"({"type": "parallel2d",
          "detector": {"count": 70, "pitch_mm": 1.0},
          "angles": {"count": 90, "range_rad": )" +
                                               std::to_string(range) + R"(},
          "volume": {"shape": [64, 64], "voxel_mm": 1.0}})");
      return (dir / name).string();
    };
    const std::string warning = "warning: the views miss part of the circle";
    for (const auto& [geometry, missing] :
         {std::pair{sim + "/geometry.json", false}, std::pair{with_range("arc.json", 0.0087), true},
          std::pair{with_range("two_turns.json", 4 * M_PI), false}}) {
      CAPTURE(geometry);
      const Run fbp = riner_cli(
          "fbp " + sim + "/sino.npy --geometry " + geometry + " --out " + (dir / "f.npy").string(),
          dir);
      REQUIRE(fbp.code == 0);
      CHECK((fbp.out.find(warning) != std::string::npos) == missing);
      const Run rec = riner_cli("reconstruct " + sim + "/sino.npy --geometry " + geometry +
                                    " --steps 20 --out " + (dir / "r").string(),
                                dir);
      REQUIRE(rec.code == 0);
      CHECK((rec.out.find(warning) != std::string::npos) == missing);
    }
  }

  TEST_CASE("partial rings: simulate --partial, reconstruct writes alpha by view and the segments") {
    // test/support/partial_scan.hpp's scan, from the CLI: 5 elements change, 2 die part-way.
    riner::test::TempDir dir;
    riner::test::write_bytes(dir / "g.json", R"({"type": "parallel2d",
      "detector": {"count": 128, "pitch_mm": 1.0}, "volume": {"shape": [96, 96], "voxel_mm": 1.0},
      "angles": {"count": 240, "range_rad": 3.141592653589793, "start_rad": 0.1}})");
    const std::string sim = (dir / "sim").string();
    REQUIRE(riner_cli("simulate --quiet --geometry " + (dir / "g.json").string() +
                          " --partial 5 --partial-dead 2 --seed 6 --out " + sim,
                      dir)
                .code == 0);
    CHECK(riner::read_array(sim + "/alpha.npy").array.shape == std::vector<std::size_t>{240, 128});
    const auto simulated = nlohmann::json::parse(riner::test::read_bytes(sim + "/simulation.json"));
    CHECK(simulated["dead_part_way"].size() == 2);
    CHECK(simulated["dead_elements"].size() == 2);
    const std::string out = (dir / "r").string();
    const Run run = riner_cli("reconstruct " + sim + "/sino.npy --set training.steps=50 --out " +
                                  out,
                              dir);
    REQUIRE(run.code == 0);
    CHECK(run.out.find("partial rings: 5 element(s) change response part-way and 2 die") !=
          std::string::npos);
    CHECK(riner::read_array(out + "/alpha_by_view.npy").array.shape ==
          std::vector<std::size_t>{240, 128});
    CHECK(riner::read_array(out + "/alpha.npy").array.shape == std::vector<std::size_t>{128});
    const auto summary = nlohmann::json::parse(riner::test::read_bytes(out + "/summary.json"));
    REQUIRE(summary["changing_elements"].size() == 7);
    CHECK(summary["changing_elements"][0]["segments"].size() == 2);
    // An element after it died read nothing: alpha and beta 0 there, as simulate's alpha (they
    // were the untrained 1 and 1, "alive").
    const riner::Array by_view = riner::read_array(out + "/alpha_by_view.npy").array;
    for (const auto& e : simulated["dead_part_way"]) {
      const std::size_t element = e.get<std::size_t>();
      CAPTURE(element);
      CHECK(by_view.data[239 * 128 + element] == 0.0f);
      bool reported = false;
      for (const auto& c : summary["changing_elements"]) {
        if (c["element"] != element) continue;
        reported = true;
        CHECK(c["dies"] == true);
        CHECK(c["segments"].back()["alpha"] == 0.0);
        CHECK(c["segments"].back()["beta"] == 0.0);
      }
      CHECK(reported);
    }
  }

  TEST_CASE("destripe: a ringed scan's FBP gains, the scan and its stripes are written") {
    riner::test::TempDir dir;
    const std::string sim = (dir / "sim").string();
    REQUIRE(riner_cli("simulate --quiet --seed 4 --out " + sim, dir).code == 0);
    const auto psnr = [&](const std::string& image) {
      const Run compare = riner_cli("compare " + image + " " + sim + "/ground_truth.nii --json", dir);
      REQUIRE(compare.code == 0);
      return nlohmann::json::parse(compare.out)["psnr_db"].get<double>();
    };
    REQUIRE(riner_cli("fbp " + sim + "/sino.npy --quiet --out " + (dir / "raw.nii").string(), dir)
                .code == 0);
    const double raw = psnr((dir / "raw.nii").string());
    const std::string out = (dir / "clean").string();
    Run run = riner_cli("destripe " + sim + "/sino.npy --reconstruct --json --out " + out, dir);
    REQUIRE(run.code == 0);
    const auto summary = nlohmann::json::parse(run.out);
    CHECK(summary["method"] == "all");
    CHECK(summary["non_finite_replaced"] == 720);  // the two dead elements' readings, interpolated
    // The quality report against the scan's own FBP: fewer rings (0.054 -> 0.008), and little
    // set to air (6 pixels at this seed: under the share the console notes).
    const auto& quality = summary["quality"];
    CHECK(quality["ring_index"].get<double>() < quality["fbp_ring_index"].get<double>() / 3.0);
    CHECK(quality["lost_object"]["share"].get<double>() < riner::kLostObjectShare);
    for (const char* f : {"sino.npy", "geometry.json", "stripes.npy", "response.npy",
                          "image.nii", "image.png", "summary.json"}) {
      CHECK(std::filesystem::exists(std::filesystem::path(out) / f));
    }
    const double destriped = psnr(out + "/image.nii");
    CHECK(destriped > raw + 2.0);  // 25.4 dB -> 28.5 at this seed
    // The destriped scan is a scan: riner reads it back, and fbp --destripe gives the same image.
    REQUIRE(riner_cli("fbp " + out + "/sino.npy --quiet --out " + (dir / "again.nii").string(),
                      dir)
                .code == 0);
    REQUIRE(riner_cli("fbp " + sim + "/sino.npy --destripe all --quiet --out " +
                          (dir / "direct.nii").string(),
                      dir)
                .code == 0);
    CHECK(std::fabs(psnr((dir / "again.nii").string()) - destriped) < 0.01);
    CHECK(std::fabs(psnr((dir / "direct.nii").string()) - destriped) < 0.01);
    expect_error(riner_cli("destripe " + sim + "/sino.npy --method wavelets --out " + out + "2",
                           dir),
                 2, "a destripe method is normalise, sorting, filtering, fitting, wavelet, large, dead or all");
    expect_error(riner_cli("fbp " + sim + "/sino.npy --destripe all --size 0 --out " +
                               (dir / "x.nii").string(),
                           dir),
                 2, "--size must be 1 or more");
  }

  TEST_CASE("bad inputs: mismatched geometry, overwriting an input, missing device") {
    riner::test::TempDir dir;
    const std::string out = (dir / "sim").string();
    REQUIRE(riner_cli("simulate --quiet --out " + out, dir).code == 0);
    riner::test::write_bytes(dir / "small.json", R"({"type": "fan2d",
      "detector": {"count": 400, "pitch_mm": 2.0}, "source_origin_mm": 370, "origin_detector_mm": 370,
      "angles": {"count": 360, "range_rad": 6.283185307179586}, "volume": {"shape": [256, 256], "voxel_mm": 1.0}})");
    expect_error(riner_cli("fbp " + out + "/sino.npy --geometry " + (dir / "small.json").string() +
                               " --out " + out + "/x.nii",
                           dir),
                 2,
                 out + "/sino.npy has shape [360, 500] but the fan2d geometry expects [360, 400]");
    expect_error(riner_cli("fbp " + out + "/sino.npy --out " + out + "/sino.npy", dir), 2,
                 out + "/sino.npy: refusing to overwrite an input file");
    // Every output a command writes is checked against its inputs before it trains or writes
    // anything (before: reconstruct trained, wrote image, alpha, beta and the rest, then
    // refused config.json; destripe wrote sino.npy, then refused geometry.json).
    const std::string first = (dir / "first").string();
    REQUIRE(riner_cli("reconstruct " + out + "/sino.npy --steps 20 --quiet --out " + first, dir)
                .code == 0);
    const std::string image_before = riner::test::read_bytes(dir / "first" / "image.nii");
    expect_error(riner_cli("reconstruct " + out + "/sino.npy --steps 20 --config " + first +
                               "/config.json --seed 3 --out " + first,
                           dir),
                 2, first + "/config.json: refusing to overwrite an input file");
    CHECK(riner::test::read_bytes(dir / "first" / "image.nii") == image_before);
    // A run into a folder of an earlier one leaves none of the earlier run's outputs beside its
    // own (here the image of another format).
    REQUIRE(
        riner_cli("reconstruct " + out + "/sino.npy --steps 20 --quiet --format npy --out " + first,
                  dir)
            .code == 0);
    CHECK_FALSE(std::filesystem::exists(dir / "first" / "image.nii"));
    CHECK(std::filesystem::exists(dir / "first" / "image.npy"));
    expect_error(riner_cli("destripe " + out + "/sino.npy --out " + out, dir), 2,
                 out + "/sino.npy: refusing to overwrite an input file");
    CHECK_FALSE(std::filesystem::exists(dir / "sim" / "stripes.npy"));
    // Values that gave an answer with exit 0: a data range SSIM cannot square, a demo of 0
    // steps (after the whole simulation), photons beyond the counts' 64 bits (all readings
    // infinite), a pitch in metres (FBP of +-4.7 for 0.1).
    expect_error(riner_cli("compare " + out + "/ground_truth.nii " + out +
                               "/ground_truth.nii --data-range -1",
                           dir),
                 2, "--data-range must be a positive number up to 1e30");
    expect_error(riner_cli("demo --steps 0 --out " + (dir / "demo0").string(), dir), 2,
                 "training.steps is 0 and there is no warm start");
    CHECK_FALSE(std::filesystem::exists(dir / "demo0"));
    expect_error(riner_cli("simulate --photons 1e20 --out " + (dir / "loud").string(), dir), 2,
                 "photons must be 0 (no noise) to 1e15");
    expect_error(riner_cli("simulate --dead 500 --out " + (dir / "dead").string(), dir), 2,
                 "every detector element would be dead: the scan would measure nothing");
    expect_error(riner_cli("simulate --mu-unit xyz --out " + (dir / "unit").string(), dir), 2,
                 "--mu-unit must be mm or cm");
    expect_error(riner_cli("fbp " + out + "/sino.npy --out " + out + "/image.png", dir), 2,
                 out + "/image.png: a PNG is an 8-bit preview");
    const Run paper = riner_cli("settings --paper", dir);
    CHECK(paper.code == 0);
    CHECK(paper.out.find("training.steps = 4000") != std::string::npos);
    // A grid no machine here holds: refused before any work (it trained about 110 s before
    // "out of memory"). 30000^2 voxels need at least 26.8 GiB; where a machine has that much,
    // the run is not tried.
    const double memory =
        static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
    if (memory < 26.0 * 1073741824.0) {
      riner::test::write_bytes(dir / "huge.json", R"({"type": "parallel2d",
        "detector": {"count": 2000, "pitch_mm": 20.0}, "angles": {"count": 10,
        "range_rad": 3.14159}, "volume": {"shape": [30000, 30000], "voxel_mm": 1.0}})");
      riner::Array readings({10, 2000}, 0.5f);
      readings.data[7] = 0.7f;  // not one value throughout (refused as such first)
      riner::write_array(dir / "huge_sino.npy", readings);
      const Run huge =
          riner_cli("reconstruct " + (dir / "huge_sino.npy").string() + " --geometry " +
                        (dir / "huge.json").string() + " --out " + (dir / "huge").string(),
                    dir);
      CHECK(huge.code == 2);
      CHECK(huge.err.find("need at least 26.8 GiB, more than the machine's") != std::string::npos);
    }
    expect_error(
        riner_cli("reconstruct " + out + "/sino.npy --seed -1 --out " + (dir / "seed").string(),
                  dir),
        2, "--seed must be 0 or more");
    expect_error(riner_cli("reconstruct " + out + "/sino.npy --report-every 0 --out " +
                               (dir / "seed").string(),
                           dir),
                 2, "--report-every must be 1 or more steps");
    riner::test::write_bytes(dir / "metres.json", R"({"type": "fan2d",
      "detector": {"count": 500, "pitch_mm": 0.002}, "source_origin_mm": 370,
      "origin_detector_mm": 370, "angles": {"count": 360, "range_rad": 6.283185307179586},
      "volume": {"shape": [256, 256], "voxel_mm": 1.0}})");
    expect_error(riner_cli("fbp " + out + "/sino.npy --geometry " + (dir / "metres.json").string() +
                               " --out " + out + "/m.nii",
                           dir),
                 2,
                 (dir / "metres.json").string() +
                     ": the detector's rays reach 0.2495 mm from the axis, under 1/20 of the "
                     "grid's half width (128 mm): check detector.pitch_mm and volume.voxel_mm "
                     "(both in mm)");
    expect_error(riner_cli("fbp " + out + "/sino.npy --out " + out + "/x.nii --device 99", dir), 1,
                 "--device=99: no such device");
    expect_error(riner_cli("fbp " + out + "/sino.npy --out " + out + "/x.dcm", dir), 2,
                 out + "/x.dcm: unknown file type '.dcm'");
    expect_error(riner_cli("compare " + out + "/sino.npy " + out + "/ground_truth.nii", dir), 2,
                 "cannot compare images of shapes [360, 500] and [256, 256]");
    expect_error(riner_cli("simulate --phantom " + out + "/sino.npy --out " + out + "/again", dir),
                 2, out + "/sino.npy has shape [360, 500] but the geometry's grid is [256, 256]");
    // A detector beside the grid, and a grid too small to check: refused before any work (the
    // grid's check ended a whole training).
    riner::test::write_bytes(dir / "beside.json", R"({"type": "fan2d",
      "detector": {"count": 500, "pitch_mm": 2.0, "offset_px": 1000}, "source_origin_mm": 370,
      "origin_detector_mm": 370, "angles": {"count": 360, "range_rad": 6.283185307179586},
      "volume": {"shape": [256, 256], "voxel_mm": 1.0}})");
    expect_error(riner_cli("fbp " + out + "/sino.npy --geometry " + (dir / "beside.json").string() +
                               " --out " + out + "/x.nii",
                           dir),
                 2,
                 (dir / "beside.json").string() +
                     ": no detector ray crosses the reconstruction grid: the rays pass");
    riner::test::write_bytes(dir / "tiny.json", R"({"type": "fan2d",
      "detector": {"count": 500, "pitch_mm": 2.0}, "source_origin_mm": 370, "origin_detector_mm": 370,
      "angles": {"count": 360, "range_rad": 6.283185307179586}, "volume": {"shape": [8, 8], "voxel_mm": 32.0}})");
    expect_error(riner_cli("reconstruct " + out + "/sino.npy --geometry " +
                               (dir / "tiny.json").string() + " --out " + out + "/tiny",
                           dir),
                 2, "the grid's slices are 8 x 8 pixels: the quality report against FBP needs");
    CHECK_FALSE(std::filesystem::exists(dir / "sim" / "tiny" / "image.nii"));
  }

  TEST_CASE("simulate from an image in 1/cm, on the reference engine") {
    riner::test::TempDir dir;
    riner::Array image({256, 256}, 0.2f);  // water in 1/cm
    riner::write_array(dir / "water.nii", image);
    const std::string out = (dir / "w").string();
    REQUIRE(riner_cli("simulate --quiet --phantom " + (dir / "water.nii").string() +
                          " --mu-unit cm --engine reference --photons 0 --dead 0 "
                          "--nonideal-fraction 0 --out " +
                          out,
                      dir)
                .code == 0);
    const riner::Array clean = riner::read_array(out + "/sino_clean.npy").array;
    const riner::Array sino = riner::read_array(out + "/sino.npy").array;
    CHECK(clean.data == sino.data);  // no noise, ideal detector
    // The central ray crosses 256 mm of 0.02 / mm.
    CHECK(clean(0, 249) == doctest::Approx(256 * 0.02).epsilon(0.01));
  }

  TEST_CASE("simulate resamples an image of another voxel size onto the grid") {
    riner::test::TempDir dir;
    riner::Array image({64, 64}, 0.02f);  // a 128 mm square of water at 2 mm
    riner::write_array(dir / "coarse.npy", image);
    const std::string common = "simulate --quiet --phantom " + (dir / "coarse.npy").string() +
                               " --photons 0 --dead 0 --nonideal-fraction 0 --out ";
    const std::string path = (dir / "coarse.npy").string();
    expect_error(riner_cli(common + (dir / "a").string(), dir), 2,
                 path +
                     " has shape [64, 64] but the geometry's grid is [256, 256] "
                     "(--phantom-spacing-mm resamples it)");
    expect_error(riner_cli(common + (dir / "b").string() + " --phantom-spacing-mm file", dir), 2,
                 path + " stores no voxel size; give --phantom-spacing-mm");
    REQUIRE(riner_cli(common + (dir / "c").string() + " --phantom-spacing-mm 2,2", dir).code == 0);
    const riner::Array truth = riner::read_array(dir / "c" / "ground_truth.nii").array;
    CHECK(truth.shape == std::vector<std::size_t>{256, 256});
    CHECK(truth(128, 128) == doctest::Approx(0.02));
    CHECK(truth(128, 10) == 0.0f);  // 118 mm from the centre: beyond the 64 mm half-width
    // The central ray crosses the 128 mm square.
    const riner::Array clean = riner::read_array(dir / "c" / "sino_clean.npy").array;
    CHECK(clean(0, 249) == doctest::Approx(128 * 0.02).epsilon(0.02));
  }

  TEST_CASE("3D: mismatched stacks exit 2; rows that read NaN or stay steady are dead, and said so") {
    riner::test::TempDir dir;
    const std::string g3 = write_small_cone3d_geometry(dir);
    const std::string sim3 = (dir / "sim3").string(), sim2 = (dir / "sim2").string();
    REQUIRE(riner_cli(
                "simulate --quiet --geometry " + g3 + " --out " + sim3, dir)
                .code == 0);
    REQUIRE(riner_cli("simulate --quiet --out " + sim2, dir).code == 0);
    expect_error(riner_cli("reconstruct " + sim3 + "/sino.npy --geometry " + sim2 +
                               "/geometry.json --out " + (dir / "a").string(),
                           dir),
                 2, sim3 + "/sino.npy has shape [36, 20, 30] but the fan2d geometry expects");
    expect_error(riner_cli("reconstruct " + sim2 + "/sino.npy --geometry " + sim3 +
                               "/geometry.json --out " + (dir / "b").string(),
                           dir),
                 2, sim2 + "/sino.npy has shape [360, 500] but the cone3d geometry expects");
    // Detector row 5 reads NaN in every view: its 30 pixels are dead for that reason. Row 10
    // reads 0 (stuck at the flat) where the phantom's shadow crosses it.
    riner::Array stack = riner::read_array(sim3 + "/sino.npy").array;
    for (std::size_t v = 0; v < 36; ++v) {
      for (std::size_t c = 0; c < 30; ++c) stack.data[(v * 20 + 5) * 30 + c] = NAN;
      for (std::size_t c = 0; c < 30; ++c) stack.data[(v * 20 + 10) * 30 + c] = 0.0f;
    }
    riner::write_array(dir / "nan_row.npy", stack);
    REQUIRE(riner_cli("reconstruct " + (dir / "nan_row.npy").string() + " --geometry " + sim3 +
                          "/geometry.json --steps 20 --quiet --out " + (dir / "c").string(),
                      dir)
                .code == 0);
    const auto summary = nlohmann::json::parse(riner::test::read_bytes(dir / "c" / "summary.json"));
    int row_five = 0, row_ten = 0, stuck_elsewhere = 0;
    for (const auto& d : summary["dead_element_reasons"]) {
      const std::size_t e = d["element"];
      if (e / 30 == 5 && d["reason"] == "no finite reading") ++row_five;
      if (d["reason"] == "stuck: steady while its neighbours vary") {
        (e / 30 == 10 ? row_ten : stuck_elsewhere)++;
      }
    }
    CHECK(row_five == 30);
    const riner::Array beta = riner::read_array(dir / "c" / "beta.npy").array;
    for (std::size_t c = 0; c < 30; ++c) CHECK(beta.data[5 * 30 + c] < 0.5f);
    MESSAGE("row 10: " << row_ten << " of 30 found stuck");
    CHECK(row_ten >= 10);  // the columns the phantom's shadow sweeps
    CHECK(stuck_elsewhere == 0);
    const riner::Array image = riner::read_array(dir / "c" / "image.nii").array;
    for (float v : image.data) REQUIRE(std::isfinite(v));
  }

  TEST_CASE("3D: row x column factors learn a detector of row x column gains better") {
    riner::test::TempDir dir;
    const std::string g3 = write_small_cone3d_geometry(dir);
    const std::string sim = (dir / "sim").string();
    REQUIRE(riner_cli("simulate --quiet --seed 2 --response-pattern rows-x-columns --geometry " +
                          g3 + " --out " + sim,
                      dir)
                .code == 0);
    expect_error(riner_cli("simulate --response-pattern rows --out " + (dir / "x").string(), dir),
                 2, "--response-pattern must be per-element or rows-x-columns");
    expect_error(riner_cli("simulate --response-pattern rows-x-columns --out " +
                               (dir / "y").string(),
                           dir),
                 2, "responses by rows x columns need a 3D detector");
    const riner::Array truth = riner::read_array(sim + "/alpha.npy").array;
    // rms of log(alpha / truth) over the live pixels, after the scale no scan can fix (a
    // common gain is a constant offset on every ray).
    auto log_error = [&](const riner::Array& alpha) {
      std::vector<double> d;
      for (std::size_t e = 0; e < truth.size(); ++e) {
        if (truth.data[e] > 0.0f) d.push_back(std::log(alpha.data[e] / truth.data[e]));
      }
      double mean = 0.0, squares = 0.0;
      for (double x : d) mean += x / static_cast<double>(d.size());
      for (double x : d) squares += (x - mean) * (x - mean) / static_cast<double>(d.size());
      return std::sqrt(squares);
    };
    double error[2];
    const char* models[2] = {"rows-x-columns", "per-element"};
    for (int m = 0; m < 2; ++m) {
      const std::string out = (dir / models[m]).string();
      const Run run = riner_cli("reconstruct " + sim + "/sino.npy --steps 400 --json --out " +
                                    out + " --set training.alpha_model=" + models[m],
                                dir);
      REQUIRE(run.code == 0);
      const auto model = nlohmann::json::parse(run.out)["alpha_model"];
      // On so small a detector the object's edges weigh more than on a real one: auto's bar
      // (0.9) is tested on larger ones (test_factor_evidence.cpp).
      CHECK(model["factor_evidence"].get<double>() > 0.8);
      CHECK(model["model"] == models[m]);
      const riner::Array alpha = riner::read_array(out + "/alpha.npy").array;
      error[m] = log_error(alpha);
      if (m == 0) {
        // What was trained is a product: a(r, c) a(s, d) = a(r, d) a(s, c).
        auto at = [&](std::size_t r, std::size_t c) { return double(alpha.data[r * 30 + c]); };
        CHECK(at(2, 3) * at(15, 27) == doctest::Approx(at(2, 27) * at(15, 3)).epsilon(1e-4));
      }
    }
    const double spread = log_error(riner::Array(truth.shape, 1.0f));
    MESSAGE("log alpha error: factors " << error[0] << ", per element " << error[1]
                                        << ", alpha = 1: " << spread);
    CHECK(error[0] < 0.6 * error[1]);
  }

  TEST_CASE("3D: the ring corrections run slice by slice on a parallel scan only when asked") {
    riner::test::TempDir dir;
    const std::string sim = simulate_small_parallel3d(dir);
    const std::string run = "reconstruct " + sim + "/sino.npy --steps 200 --json --out ";
    const Run plain = riner_cli(run + (dir / "plain").string(), dir);
    REQUIRE(plain.code == 0);
    CHECK(nlohmann::json::parse(plain.out)["slice_ring_corrections"].is_null());
    const Run sliced =
        riner_cli(run + (dir / "sliced").string() + " --set rings.slice_by_slice=true", dir);
    REQUIRE(sliced.code == 0);
    const auto rings = nlohmann::json::parse(sliced.out)["slice_ring_corrections"];
    CHECK(rings["slices_corrected"] == 20);  // every slice lies at a row's height
    CHECK(rings["note"] == "");
  }

  TEST_CASE("raw projections: a TIFF folder with flats and darks gives the measurement's image") {
    riner::test::TempDir dir;
    const std::string sim = simulate_small_parallel3d(dir);
    const riner::Array rho = riner::read_array(sim + "/sino_clean.npy").array;
    // The scanner's files: I = D + (F - D) exp(-rho), a flat that varies across the detector
    // (three frames, averaged), a dark of two frames, one reading at the dark.
    const std::size_t pixels = 20 * 30;
    riner::Array flats({3, 20, 30}), darks({2, 20, 30});
    for (std::size_t p = 0; p < pixels; ++p) {
      for (std::size_t f = 0; f < 3; ++f) {
        flats.data[f * pixels + p] = 4000.0f + 10.0f * static_cast<float>(p % 30) + 100.0f * f;
      }
      darks.data[p] = 90.0f;
      darks.data[pixels + p] = 110.0f;
    }
    std::filesystem::create_directory(dir / "raw");
    std::filesystem::create_directory(dir / "raw" / "projections");
    for (std::size_t v = 0; v < 36; ++v) {
      riner::Array view({20, 30});
      for (std::size_t p = 0; p < pixels; ++p) {
        const float flat = 4100.0f + 10.0f * static_cast<float>(p % 30);
        view.data[p] = 100.0f + (flat - 100.0f) * std::exp(-rho.data[v * pixels + p]);
      }
      if (v == 7) view.data[31] = 100.0f;  // at the dark: invalid
      riner::write_array(dir / "raw" / "projections" / ("proj_" + std::to_string(v) + ".tif"),
                         view);
    }
    for (std::size_t f = 0; f < 3; ++f) {
      riner::write_array(
          dir / "raw" / ("flat_" + std::to_string(f) + ".tif"),
          riner::Array({20, 30}, std::vector<float>(flats.data.begin() + f * pixels,
                                                    flats.data.begin() + (f + 1) * pixels)));
    }
    riner::write_array(dir / "raw" / "dark.npy", darks);
    std::filesystem::copy_file(dir / "g3.json", dir / "raw" / "geometry.json");
    const std::string raw = (dir / "raw").string();
    // The geometry is found beside the folder; the flats are a quoted pattern.
    const Run fbp =
        riner_cli("fbp " + raw + "/projections --flat '" + raw + "/flat_*.tif' --dark " + raw +
                      "/dark.npy --out " + raw + "/fbp.nii --json",
                  dir);
    REQUIRE(fbp.code == 0);
    const auto summary = nlohmann::json::parse(fbp.out);
    CHECK(summary["flat_field"]["flat_frames"] == 3);
    CHECK(summary["inputs"]["flat"] == raw + "/flat_*.tif");  // what was read, as given
    CHECK(summary["inputs"]["dark"] == raw + "/dark.npy");
    CHECK(summary["inputs"]["row"].is_null());
    CHECK(summary["inputs"]["geometry"] == raw + "/geometry.json");  // found beside the folder
    CHECK(summary["flat_field"]["dark_frames"] == 2);
    CHECK(summary["flat_field"]["invalid_readings"] == 1);
    CHECK(summary["non_finite_replaced"] == 1);
    // From inside the folder, as "." or as a pattern there: the geometry beside the folder
    // ("no geometry.json beside it": "." and "proj_*.tif" had no parent to look in).
    for (const char* scan_name : {".", "'proj_*.tif'"}) {
      CAPTURE(scan_name);
      const std::string command = "cd " + raw + "/projections && " + RINER_CLI_PATH + " fbp " +
                                  scan_name + " --flat ../flat_0.tif --out ../inside.nii --quiet";
      CHECK(std::system(command.c_str()) == 0);
    }
    // A folder copied from a Mac holds "._proj_0.tif" beside each image ("not a readable TIFF").
    riner::test::write_bytes(dir / "raw" / "projections" / "._proj_0.tif", "Mac OS X metadata");
    CHECK(riner_cli("fbp " + raw + "/projections --flat " + raw + "/flat_0.tif --out " + raw +
                        "/mac.nii --quiet",
                    dir)
              .code == 0);
    // An unquoted pattern: the shell hands riner its files.
    expect_error(riner_cli("fbp " + raw + "/projections/proj_*.tif --flat " + raw +
                               "/flat_0.tif --out " + raw + "/glob.nii",
                           dir),
                 2,
                 "unexpected argument '" + raw +
                     "/projections/proj_1.tif' (the shell expanded a "
                     "pattern into its files: quote it, 'proj_*.tif')");
    REQUIRE(riner_cli("fbp " + sim + "/sino_clean.npy --out " + raw + "/fbp_rho.nii --quiet", dir)
                .code == 0);
    const Run compare =
        riner_cli("compare " + raw + "/fbp.nii " + raw + "/fbp_rho.nii --json", dir);
    REQUIRE(compare.code == 0);
    CHECK(nlohmann::json::parse(compare.out)["psnr_db"].get<double>() > 60.0);
    // Reconstruct reads the same and reports the normalisation in summary.json.
    REQUIRE(riner_cli("reconstruct " + raw + "/projections --flat '" + raw +
                          "/flat_*.tif' --dark " + raw + "/dark.npy --steps 20 --quiet --out " +
                          raw + "/rec",
                      dir)
                .code == 0);
    const auto rec = nlohmann::json::parse(riner::test::read_bytes(dir / "raw/rec/summary.json"));
    CHECK(rec["flat_field"]["invalid_readings"] == 1);
    CHECK(rec["non_finite_measurements"] == 1);
    // One scan JSON naming the same files (relative to it) gives the same image.
    nlohmann::json scan = nlohmann::json::parse(riner::test::read_bytes(dir / "g3.json"));
    scan["files"] = {{"projections", "projections"}, {"flat", "flat_*.tif"}, {"dark", "dark.npy"}};
    riner::test::write_bytes(dir / "raw" / "scan.json", scan.dump());
    REQUIRE(riner_cli("fbp " + raw + "/scan.json --out " + raw + "/fbp_scan.nii --quiet", dir)
                .code == 0);
    CHECK(riner::read_array(dir / "raw/fbp_scan.nii").array.data ==
          riner::read_array(dir / "raw/fbp.nii").array.data);
    expect_error(riner_cli("fbp " + raw + "/scan.json --flat " + raw + "/dark.npy --out " + raw +
                               "/x.nii",
                           dir),
                 2, "a scan JSON names its own data and geometry");
    scan["files"] = {{"projections", "projections"}, {"dark", "dark.npy"}};
    riner::test::write_bytes(dir / "raw" / "no_flat.json", scan.dump());
    expect_error(riner_cli("fbp " + raw + "/no_flat.json --out " + raw + "/x.nii", dir), 2,
                 raw + "/no_flat.json: files.dark needs files.flat");
    scan["files"] = {{"projections", "projections"}};
    riner::test::write_bytes(dir / "raw" / "no_flat.json", scan.dump());
    expect_error(riner_cli("fbp " + raw + "/no_flat.json --out " + raw + "/x.nii", dir), 2,
                 raw + "/no_flat.json: files.projections needs files.flat");
    scan["files"] = {{"measurement", "sino.npy"}, {"flats", "flat_0.tif"}};
    riner::test::write_bytes(dir / "raw" / "typo.json", scan.dump());
    expect_error(riner_cli("fbp " + raw + "/typo.json --out " + raw + "/x.nii", dir), 2,
                 raw + "/typo.json: files.flats is not a scan file");
    expect_error(riner_cli("fbp " + (dir / "g3.json").string() + " --out " + raw + "/x.nii", dir),
                 2, (dir / "g3.json").string() + ": a geometry without \"files\"");
    // Bad raw input: one line, exit 2. Raw projections without their flat field are no line
    // integrals (they were reconstructed into garbage without a word).
    expect_error(riner_cli("fbp " + raw + "/projections --out " + raw + "/x.nii", dir), 2,
                 raw + "/projections: 99% of the readings exceed 20 (the 1st percentile: ");
    expect_error(
        riner_cli("fbp " + raw + "/projections --dark " + raw + "/dark.npy --out " + raw + "/x.nii",
                  dir),
        2, "--dark needs --flat");
    // An unset shell variable: no dark field at all, without a word.
    expect_error(riner_cli("fbp " + raw + "/projections --flat " + raw + "/flat_0.tif --dark '' " +
                               "--out " + raw + "/x.nii",
                           dir),
                 2, "--dark needs a file (got an empty name)");
    expect_error(riner_cli("fbp " + raw + "/projections --flat " + raw + "/dark.npy --dark " + raw +
                               "/flat_0.tif --out " + raw + "/x.nii",
                           dir),
                 2, raw + "/projections: no projection reading is above its dark field");
    riner::write_array(dir / "raw" / "wide.tif", riner::Array({20, 31}, 1.0f));
    expect_error(
        riner_cli("fbp " + raw + "/projections --flat " + raw + "/wide.tif --out " + raw + "/x.nii",
                  dir),
        2, raw + "/wide.tif: the flat field of shape [20, 31] is neither one frame of a view's");
    // The flats after the scan named no file at all.
    expect_error(
        riner_cli("fbp " + raw + "/projections --flat " + raw + "/flat_0.tif --flat-after " + raw +
                      "/wide.tif --out " + raw + "/x.nii",
                  dir),
        2, raw + "/wide.tif: the flat field after the scan of shape [20, 31] is neither");
    expect_error(riner_cli("fbp '" + raw + "/nothing_*.tif' --flat " + raw + "/wide.tif --out " +
                               raw + "/x.nii",
                           dir),
                 2, raw + "/nothing_*.tif: no file matches the pattern");
    // A pattern matching the other series' files: an audit's 'flat_*.tif' took the flats
    // after the scan ('flat_end_*.tif') for flats before it, the drift halved without a word.
    std::filesystem::copy_file(dir / "raw" / "flat_0.tif", dir / "raw" / "flat_end_0.tif");
    expect_error(riner_cli("fbp " + raw + "/projections --flat '" + raw + "/flat_*.tif' " +
                               "--flat-after " + raw + "/flat_end_0.tif --out " + raw + "/x.nii",
                           dir),
                 2, raw + "/flat_end_0.tif is read as the flat field and as the flat field after");
    // The same flats before and after: no drift, no mistake.
    const Run same = riner_cli("fbp " + raw + "/projections --flat " + raw + "/flat_0.tif " +
                                   "--flat-after " + raw + "/flat_0.tif --out " + raw + "/same.nii",
                               dir);
    CHECK(same.code == 0);
    CHECK(same.err == "");
  }

  TEST_CASE("center finds a forgotten offset; --offset-px auto uses it") {
    riner::test::TempDir dir;
    std::string angles;
    for (int i = 0; i <= 90; ++i) angles += (i ? ", " : "") + std::to_string(M_PI * i / 90.0);
    auto geometry = [&](double offset) {
      return R"({"type": "parallel2d", "detector": {"count": 120, "pitch_mm": 1.0, "offset_px": )" +
             std::to_string(offset) + R"(}, "angles_rad": [)" + angles +
             R"(], "volume": {"shape": [96, 96], "voxel_mm": 1.0}})";
    };
    riner::test::write_bytes(dir / "true.json", geometry(4.6));
    riner::test::write_bytes(dir / "forgot.json", geometry(0.0));
    const std::string sim = (dir / "sim").string();
    REQUIRE(riner_cli("simulate --quiet --seed 2 --geometry " + (dir / "true.json").string() +
                          " --out " + sim,
                      dir)
                .code == 0);
    const Run center = riner_cli(
        "center " + sim + "/sino.npy --geometry " + (dir / "forgot.json").string() + " --json",
        dir);
    REQUIRE(center.code == 0);
    const auto e = nlohmann::json::parse(center.out);
    CHECK(std::fabs(e["offset_px"].get<double>() - 4.6) < 0.2);
    CHECK(e["geometry_offset_px"] == 0.0);
    const Run fbp =
        riner_cli("fbp " + sim + "/sino.npy --geometry " + (dir / "forgot.json").string() +
                      " --offset-px auto --out " + sim + "/auto.nii --json",
                  dir);
    REQUIRE(fbp.code == 0);
    CHECK(nlohmann::json::parse(fbp.out)["centre"]["offset_px"] == e["offset_px"]);
    expect_error(riner_cli("center " + sim + "/sino.npy --geometry " + sim + "/missing.json", dir),
                 2, sim + "/missing.json");
  }

  TEST_CASE("a 360-degree scan given 180 degrees of angles: center stops, fbp warns") {
    // The Shepp-Logan over a full turn with the paper's rings and noise, then the same readings
    // under a half-turn's angles, a common mistake: center's pairs half a turn apart (by the
    // angles) put the axis tens of pixels astray, and the reconstruction is garbage.
    riner::test::TempDir dir;
    const auto geometry = [&](const char* range) {
      return std::string(R"({"type": "parallel2d", "detector": {"count": 120, "pitch_mm": 1.0,
          "offset_px": 2.5}, "angles": {"count": 180, "range_rad": )") +
             range + R"(}, "volume": {"shape": [96, 96], "voxel_mm": 1.0}})";
    };
    riner::test::write_bytes(dir / "full.json", geometry("6.283185307179586"));
    riner::test::write_bytes(dir / "half.json", geometry("3.141592653589793"));
    const std::string sim = (dir / "sim").string();
    REQUIRE(riner_cli("simulate --quiet --seed 3 --geometry " + (dir / "full.json").string() +
                          " --out " + sim,
                      dir)
                .code == 0);
    const std::string wrong = sim + "/sino.npy --geometry " + (dir / "half.json").string();
    const std::string doubt =
        "the views cover a full turn (360 degrees), the geometry's angles 179.0 degrees";
    expect_error(riner_cli("center " + wrong, dir), 2, "no centre: " + doubt);
    expect_error(riner_cli("fbp " + wrong + " --offset-px auto --out " + sim + "/a.nii", dir), 2,
                 "no centre: " + doubt);
    const Run fbp = riner_cli("fbp " + wrong + " --out " + sim + "/wrong.nii", dir);
    CHECK(fbp.code == 0);
    CHECK(fbp.out.find("warning: " + doubt) != std::string::npos);
    // Under its own angles: no word of it.
    const Run right = riner_cli("fbp " + sim + "/sino.npy --out " + sim + "/right.nii", dir);
    CHECK(right.code == 0);
    CHECK(right.out.find("the views cover") == std::string::npos);
    const Run center = riner_cli("center " + sim + "/sino.npy --json", dir);
    REQUIRE(center.code == 0);
    CHECK(std::fabs(nlohmann::json::parse(center.out)["offset_px"].get<double>() - 2.5) < 0.3);
    CHECK(nlohmann::json::parse(center.out)["geometry_doubts"].empty());
    // The sample slides 4 px across the turn, steadily or in one jump near its end: its last
    // view no longer matches its first as it is, and its mirror pairs match worse. A review
    // found that absence of a full turn's evidence read as a half-turn ("no centre"); a
    // half-turn needs its own evidence now.
    const riner::Array sino = riner::read_array(sim + "/sino.npy").array;
    const std::size_t views = sino.shape[0], n_u = sino.shape[1];
    for (const bool jump : {false, true}) {
      CAPTURE(jump);
      riner::Array drifted = sino;
      for (std::size_t v = 0; v < views; ++v) {
        const double t = static_cast<double>(v) / static_cast<double>(views - 1);
        const double shift = jump ? (v >= views * 9 / 10 ? 4.0 : 0.0) : 4.0 * t;
        for (std::size_t u = 0; u < n_u; ++u) {
          const double x = std::clamp(static_cast<double>(u) - shift, 0.0, n_u - 1.0);
          const auto k = std::min(static_cast<std::size_t>(x), n_u - 2);
          const double w = x - static_cast<double>(k);
          const float* row = sino.ptr() + v * n_u;
          drifted.data[v * n_u + u] = static_cast<float>((1.0 - w) * row[k] + w * row[k + 1]);
        }
      }
      const std::string file = sim + (jump ? "/jump.npy" : "/drift.npy");
      riner::write_array(file, drifted);
      const Run drift = riner_cli("center " + file + " --geometry " + sim + "/geometry.json", dir);
      CAPTURE(drift.err);
      CHECK(drift.code == 0);
      CHECK(drift.out.find("the views cover") == std::string::npos);
    }
  }

  TEST_CASE("a fan whose source-detector distance was given as origin_detector_mm: a warning") {
    // The paper's fan (source and detector 370 mm from the axis) under TIGRE's mistake: 740 mm
    // given where riner wants the axis-detector distance. Its rays then pair with the wrong
    // conjugates and the reconstruction is blurred and bent.
    riner::test::TempDir dir;
    const std::string sim = (dir / "sim").string();
    REQUIRE(riner_cli("simulate --quiet --seed 4 --out " + sim, dir).code == 0);
    nlohmann::json g = nlohmann::json::parse(riner::test::read_bytes(sim + "/geometry.json"));
    g["origin_detector_mm"] = 740.0;
    riner::test::write_bytes(dir / "sdd.json", g.dump());
    const std::string doubt =
        "warning: the fan's rays meet their conjugates where the source sits 740 mm from the "
        "detector, 0.67 times the geometry's 1110 mm (source_origin_mm 370 + origin_detector_mm "
        "740)";
    const Run fbp = riner_cli("fbp " + sim + "/sino.npy --geometry " + (dir / "sdd.json").string() +
                                  " --out " + sim + "/wrong.nii",
                              dir);
    CHECK(fbp.code == 0);
    CHECK(fbp.out.find(doubt) != std::string::npos);
    const Run center = riner_cli(
        "center " + sim + "/sino.npy --geometry " + (dir / "sdd.json").string() + " --json", dir);
    REQUIRE(center.code == 0);
    const nlohmann::json e = nlohmann::json::parse(center.out);
    REQUIRE(e["geometry_doubts"].size() == 1);
    CHECK(("warning: " + e["geometry_doubts"][0].get<std::string>()).find(doubt) == 0);
    CHECK(std::fabs(e["offset_px"].get<double>() - g["detector"]["offset_px"].get<double>()) < 0.5);
    const Run right = riner_cli("fbp " + sim + "/sino.npy --out " + sim + "/right.nii", dir);
    CHECK(right.code == 0);
    CHECK(right.out.find("conjugates") == std::string::npos);
    // Turning the other way: center has no answer (its conjugates pair the wrong way round).
    nlohmann::json reversed =
        nlohmann::json::parse(riner::test::read_bytes(sim + "/geometry.json"));
    reversed["angles"]["range_rad"] = -reversed["angles"]["range_rad"].get<double>();
    riner::test::write_bytes(dir / "reversed.json", reversed.dump());
    expect_error(
        riner_cli("center " + sim + "/sino.npy --geometry " + (dir / "reversed.json").string(),
                  dir),
        2, "no centre: the fan's rays meet their conjugates with the views turning the other way");
    // An offset whose sign alone is wrong (60 px, and a half acquisition's 200) is no reversed
    // sense, and the axis is found at its mirror image (a review's: -155.10 for 60, and "no
    // centre: ... turning the other way" for 200).
    for (const double offset : {60.0, 200.0}) {
      CAPTURE(offset);
      nlohmann::json shifted =
          nlohmann::json::parse(riner::test::read_bytes(sim + "/geometry.json"));
      shifted["detector"]["offset_px"] = offset;
      riner::test::write_bytes(dir / "shifted.json", shifted.dump());
      const std::string moved = (dir / "moved").string();
      std::filesystem::remove_all(moved);
      REQUIRE(riner_cli("simulate --quiet --seed 2 --geometry " + (dir / "shifted.json").string() +
                            " --out " + moved,
                        dir)
                  .code == 0);
      shifted["detector"]["offset_px"] = -offset;
      riner::test::write_bytes(dir / "sign.json", shifted.dump());
      const Run found = riner_cli(
          "center " + moved + "/sino.npy --geometry " + (dir / "sign.json").string() + " --json",
          dir);
      CAPTURE(found.err);
      REQUIRE(found.code == 0);
      CHECK(std::fabs(nlohmann::json::parse(found.out)["offset_px"].get<double>() - offset) < 0.5);
      CHECK(found.out.find("turning the other way") == std::string::npos);
    }
  }

  TEST_CASE("center: a narrow object, among strong rings or none, 0 to 6 px off the middle") {
    // The built-in phantom at 0.1 mm voxels fills 11-13 of 160 columns. With the detector's
    // responses (+-25%) offsetting every column, the stripes' mirror images outweighed the
    // object's: seeds 1-5 put the axis 2.2 to 39.2 px astray (an audit's: 28.85). On an ideal
    // detector the search ended at its end 6.25 px off (the object's mirror image sent off the
    // detector matched nothing, cheaply). Now within a pixel with rings (their column means
    // taken out leave a lean), within 0.3 px without.
    riner::test::TempDir dir;
    const auto geometry = [&](double o) {
      return R"({"type": "parallel2d", "detector": {"count": 160, "pitch_mm": 1.0, "offset_px": )" +
             std::to_string(o) +
             R"(}, "angles": {"count": 180, "range_rad": 3.141592653589793},
                "volume": {"shape": [128, 128], "voxel_mm": 0.1}})";
    };
    riner::test::write_bytes(dir / "forgot.json", geometry(0.0));
    for (const bool rings : {true, false}) {
      for (const double offset : {0.0, 3.4, -6.25}) {
        CAPTURE(rings);
        CAPTURE(offset);
        riner::test::write_bytes(dir / "true.json", geometry(offset));
        const std::string sim = (dir / "sim").string();
        std::filesystem::remove_all(sim);
        REQUIRE(riner_cli("simulate --quiet --seed 2 --geometry " + (dir / "true.json").string() +
                              (rings ? "" : " --photons 0 --nonideal-fraction 0 --dead 0") +
                              " --out " + sim,
                          dir)
                    .code == 0);
        const Run center = riner_cli(
            "center " + sim + "/sino.npy --geometry " + (dir / "forgot.json").string() + " --json",
            dir);
        REQUIRE(center.code == 0);
        const double found = nlohmann::json::parse(center.out)["offset_px"].get<double>();
        CAPTURE(found);
        CHECK(std::fabs(found - offset) < (rings ? 1.0 : 0.3));
      }
    }
  }

  TEST_CASE("a beam that drifts: flats before and after interpolated by view, a drift said") {
    riner::test::TempDir dir;
    // A disc (0.02 / mm, radius 15) in a parallel beam whose light falls 5% over 60 views.
    const std::size_t views = 60, elements = 48;
    riner::Array rho({views, elements}), raw({views, elements});
    riner::Array before({2, elements}), after({2, elements});
    auto beam = [](double at) { return 5000.0 * (1.0 - 0.05 * (at + 0.5) / 60.0); };
    for (std::size_t e = 0; e < elements; ++e) {
      const double s = static_cast<double>(e) - 23.5;
      const double chord = std::fabs(s) < 15.0 ? 2.0 * std::sqrt(225.0 - s * s) * 0.02 : 0.0;
      for (std::size_t f = 0; f < 2; ++f) {
        before.data[f * elements + e] = static_cast<float>(beam(-0.5));
        after.data[f * elements + e] = static_cast<float>(beam(59.5));
      }
      for (std::size_t v = 0; v < views; ++v) {
        rho.data[v * elements + e] = static_cast<float>(chord);
        raw.data[v * elements + e] =
            static_cast<float>(beam(static_cast<double>(v)) * std::exp(-chord));
      }
    }
    riner::write_array(dir / "raw.npy", raw);
    riner::write_array(dir / "rho.npy", rho);
    riner::write_array(dir / "before.npy", before);
    riner::write_array(dir / "after.npy", after);
    riner::test::write_bytes(dir / "geometry.json", R"({"type": "parallel2d",
        "detector": {"count": 48, "pitch_mm": 1.0},
        "angles": {"count": 60, "range_rad": 3.141592653589793},
        "volume": {"shape": [48, 48], "voxel_mm": 1.0}})");
    const std::string d = dir.path().string() + "/";
    // The flats before alone: the air's reading climbs 5% over the scan, and riner says so.
    Run run = riner_cli("fbp " + d + "raw.npy --flat " + d + "before.npy --out " + d +
                            "stale.nii --json",
                        dir);
    REQUIRE(run.code == 0);
    nlohmann::json summary = nlohmann::json::parse(run.out);
    CHECK(summary["flat_field"]["air_drifts"] == true);
    CHECK(summary["flat_field"]["air_last"].get<double>() > 0.04);
    CHECK(run.err.find("give flats from after the scan too (--flat-after)") != std::string::npos);
    // Before and after: each view's flat interpolated, the image that of the true readings.
    run = riner_cli("fbp " + d + "raw.npy --flat " + d + "before.npy --flat-after " + d +
                        "after.npy --out " + d + "drift.nii --json",
                    dir);
    CAPTURE(run.err);
    REQUIRE(run.code == 0);
    summary = nlohmann::json::parse(run.out);
    CHECK(summary["flat_field"]["flat_series"] == 2);
    CHECK(summary["flat_field"]["flat_change"].get<double>() ==
          doctest::Approx(-0.05).epsilon(0.01));
    CHECK(summary["flat_field"]["air_drifts"] == false);
    CHECK(run.err.find("drifted") == std::string::npos);
    REQUIRE(riner_cli("fbp " + d + "rho.npy --out " + d + "truth.nii --quiet", dir).code == 0);
    run = riner_cli("compare " + d + "drift.nii " + d + "truth.nii --json", dir);
    REQUIRE(run.code == 0);
    CHECK(nlohmann::json::parse(run.out)["psnr_db"].get<double>() > 60.0);
    run = riner_cli("compare " + d + "stale.nii " + d + "truth.nii --json", dir);
    REQUIRE(run.code == 0);
    CHECK(nlohmann::json::parse(run.out)["psnr_db"].get<double>() < 40.0);
    // Flats after without flats before: said.
    expect_error(riner_cli("fbp " + d + "raw.npy --flat-after " + d + "after.npy --out " + d +
                               "x.nii",
                           dir),
                 2, "--flat-after needs --flat (the flats before the scan)");
  }

  TEST_CASE("destripe on the shared neutron360: the rods are no large stripes, a loss is said") {
    const std::filesystem::path scan = riner::test::shared_data("neutron360/sino.npy");
    if (scan.empty()) {
      MESSAGE("skipped: ../shared/data/neutron360 is not beside the checkout");
      return;
    }
    riner::test::TempDir dir;
    const auto run_all = [&](const std::string& name, const std::string& flags) {
      const Run run = riner_cli("destripe " + scan.string() + " --method all --reconstruct --out " +
                                    (dir / name).string() + " --json" + flags,
                                dir);
      REQUIRE(run.code == 0);
      return std::make_pair(run, nlohmann::json::parse(run.out));
    };
    // Vo's rule alone flagged 149 of 503 elements, and replacing them lost 785 pixels of
    // object; with every quarter of the ranks required to carry the offset, none. The
    // combination's sorting step at its window of 5 then loses 26 pixels (0.01%), below the
    // console's note; at 31 it loses 332 (0.2%), which the console says (at algotom's 21 it
    // lost 361 before the large-stripe step kept the object's curve, 173 since).
    const auto [run, summary] = run_all("all", "");
    CHECK(summary["large_stripe_elements"].size() <= 5);
    // Two elements fail in part of the views, each with its neighbours (algorithm 6: 69 specks
    // per 10k pixels to 2); a body's edge is no such element.
    const auto dead = summary["dead_elements"].get<std::vector<std::size_t>>();
    CHECK(dead == std::vector<std::size_t>{313, 314, 315, 345, 346, 347});
    CHECK(run.err.find("were found as large stripes") == std::string::npos);
    CHECK(summary["quality"]["lost_object"]["pixels"].get<std::size_t>() < 100);
    CHECK(run.err.find("shows air where FBP clearly sees object") == std::string::npos);
    const auto [wide, wide_summary] = run_all("all31", " --size 31");
    CHECK(wide.err.find("shows air where FBP clearly sees object") != std::string::npos);
    CHECK(wide_summary["quality"]["lost_object"]["pixels"].get<std::size_t>() > 200);
  }

  TEST_CASE("a Data Exchange file (shared tooth): its flats and darks, one row, the shared rho") {
    const std::filesystem::path tooth = riner::test::shared_data("tooth/tooth.h5");
    if (tooth.empty()) {
      MESSAGE("skipped: ../shared/data/tooth is not beside the checkout");
      return;
    }
    riner::test::TempDir dir;
    const std::string out = dir.path().string();
    const Run fbp =
        riner_cli("fbp " + tooth.string() + " --row 0 --out " + out + "/raw.nii --json", dir);
    REQUIRE(fbp.code == 0);
    const auto summary = nlohmann::json::parse(fbp.out);
    CHECK(summary["flat_field"]["flat_frames"] == 10);
    CHECK(summary["flat_field"]["dark_frames"] == 10);
    REQUIRE(riner_cli("fbp " + tooth.parent_path().string() + "/sino_row0.npy --out " + out +
                          "/shared.nii --quiet",
                      dir)
                .code == 0);
    const Run compare = riner_cli("compare " + out + "/raw.nii " + out + "/shared.nii --json", dir);
    REQUIRE(compare.code == 0);
    CHECK(nlohmann::json::parse(compare.out)["mae"].get<double>() < 1e-6);
    // The whole stack under its 2D geometry: one slice per row, as reconstruct takes it (it
    // was refused: "pick a detector row with --row"); its row 0 is the row's own FBP.
    REQUIRE(riner_cli("fbp " + tooth.string() + " --out " + out + "/rows.nii --quiet", dir).code ==
            0);
    const riner::Array rows = riner::read_array(out + "/rows.nii").array;
    const riner::Array row0 = riner::read_array(out + "/raw.nii").array;
    REQUIRE(rows.shape == std::vector<std::size_t>{2, row0.shape[0], row0.shape[1]});
    double worst = 0.0;
    for (std::size_t i = 0; i < row0.size(); ++i)
      worst = std::max(worst, static_cast<double>(std::fabs(rows.data[i] - row0.data[i])));
    CHECK(worst < 1e-5);
    // A stack of one row is that row's 2D scan (it read as a volume of one slice).
    riner::Array one = riner::read_array(tooth.parent_path() / "sino_row0.npy").array;
    one.shape = {one.shape[0], 1, one.shape[1]};
    std::filesystem::create_directories(dir / "one");
    riner::write_array(dir / "one" / "stack.npy", one);
    std::filesystem::copy_file(tooth.parent_path() / "geometry.json",
                               dir / "one" / "geometry.json");
    REQUIRE(riner_cli("fbp " + (dir / "one" / "stack.npy").string() + " --out " + out +
                          "/one.nii --quiet",
                      dir)
                .code == 0);
    const riner::Array one_image = riner::read_array(out + "/one.nii").array;
    REQUIRE(one_image.shape == row0.shape);
    CHECK(one_image.data == riner::read_array(out + "/shared.nii").array.data);
    // riner center (and destripe) take the stack alike (they asked for --row): both rows.
    const Run centre = riner_cli("center " + tooth.string() + " --json", dir);
    REQUIRE(centre.code == 0);
    CHECK(nlohmann::json::parse(centre.out)["offset_px"].get<double>() ==
          doctest::Approx(23.98).epsilon(0.002));
    expect_error(riner_cli("fbp " + tooth.string() + " --row 2 --out " + out + "/x.nii", dir), 2,
                 tooth.string() + ": no detector row 2: the stack [181, 2, 640] has rows 0..1");
    // A row under a 3D geometry, and a row of a single sinogram: said what --row is for (they
    // read "has shape [181, 640] but the geometry expects ..." and "no detector row 1 in frames
    // of shape [459, 503]").
    riner::write_text(dir / "g3.json",
                      R"({"type": "parallel3d", "detector": {"count": [640, 2], "pitch_mm": [1.0, 1.0]},
                          "angles": {"count": 181, "start_rad": 0, "range_rad": 3.141592653589793},
                          "volume": {"shape": [2, 64, 64], "voxel_mm": 10.0}})");
    expect_error(riner_cli("fbp " + tooth.string() + " --geometry " + (dir / "g3.json").string() +
                               " --row 1 --out " + out + "/x.nii",
                           dir),
                 2,
                 "a detector row (--row) is reconstructed as one slice under a 2D geometry; "
                 "the geometry is parallel3d");
    riner::write_array(dir / "sino.npy", riner::Array({181, 640}, 0.1f));
    riner::write_text(dir / "geometry.json",
                      riner::Geometry::load(tooth.parent_path() / "geometry.json").to_json());
    expect_error(
        riner_cli("fbp " + (dir / "sino.npy").string() + " --row 1 --out " + out + "/x.nii", dir),
        2,
        (dir / "sino.npy").string() +
            ": a detector row is picked from a projection stack [views, rows, columns]; this is "
            "[181, 640]");
  }

  TEST_CASE("settings: one table for the list, docs/settings.md, --set and config.json") {
    riner::test::TempDir dir;
    const Run list = riner_cli("settings --json", dir);
    REQUIRE(list.code == 0);
    const auto settings = nlohmann::json::parse(list.out)["settings"];
    CHECK(settings.size() >= 60);
    // docs/settings.md is what `riner settings --markdown` prints.
    const Run markdown = riner_cli("settings --markdown", dir);
    REQUIRE(markdown.code == 0);
    const std::string page =
        riner::test::read_bytes(std::string(RINER_SOURCE_DIR) + "/docs/settings.md");
    CHECK_MESSAGE(page == markdown.out,
                  "docs/settings.md is out of date: riner settings --markdown > docs/settings.md");
    CHECK(markdown.out.find("| `training.steps` | `-1` |") != std::string::npos);

    const std::string sim = (dir / "sim").string();
    REQUIRE(riner_cli("simulate --quiet --seed 3 --out " + sim, dir).code == 0);
    const Run run = riner_cli("reconstruct " + sim +
                                  "/sino.npy --quiet --set "
                                  "training.steps=20,training.sampler=mixed,"
                                  "rings.response_air_fraction=0.05 --out " +
                                  (dir / "r").string(),
                              dir);
    REQUIRE(run.code == 0);
    const auto written = nlohmann::json::parse(riner::test::read_bytes(dir / "r" / "config.json"));
    CHECK(written["training"]["steps"] == 20);
    CHECK(written["training"]["sampler"] == "mixed");
    CHECK(written["rings"]["response_air_fraction"] == 0.05);
    // The simulated dead elements read inf in every view: dead for that reason, said so.
    const auto summary = nlohmann::json::parse(riner::test::read_bytes(dir / "r" / "summary.json"));
    const auto reasons = summary["dead_element_reasons"];
    REQUIRE(reasons.size() == summary["dead_elements"].size());
    int unreadable = 0;
    for (const auto& d : reasons) {
      const std::string why = d["reason"];
      CHECK((why == "no finite reading" || why == "beta below 0.5"));
      if (why == "no finite reading") {
        ++unreadable;
        CHECK(d["invalid_readings"].get<int>() > 0);
      } else {
        CHECK(d["beta"].get<double>() < 0.5);
      }
    }
    CHECK(unreadable == 2);
    // beta.npy and alpha.npy say the same (before: beta ~0.7-1 and alpha 1 for an element with
    // no finite reading, which gets no gradient).
    const riner::Array beta = riner::read_array(dir / "r" / "beta.npy").array;
    const riner::Array alpha = riner::read_array(dir / "r" / "alpha.npy").array;
    for (const auto& d : reasons) {
      const std::size_t e = d["element"];
      CHECK(beta.data[e] < 0.5f);
      CHECK(alpha.data[e] == 0.0f);
    }
    // Memory: the process held at least the scan (360 views x 500 floats) on the device, and
    // the host at least that too.
    const double scan_mb = 360.0 * 500 * 4 / 1048576;
    CHECK(summary["memory"]["peak_device_buffers_mb"].get<double>() > scan_mb);
    CHECK(summary["memory"]["peak_host_mb"].get<double>() > scan_mb);
    // Coverage: every drawn ray counted once: 20 steps of the mixed sampler's uniform rays plus
    // its views x elements block.
    const auto coverage = summary["coverage"];
    const auto& t = written["training"];
    CHECK(coverage["rays"].get<long>() ==
          20 * (t["rays_per_step"].get<long>() +
                t["views_per_step"].get<long>() * t["elements_per_step"].get<long>()));
    CHECK(coverage["rays_per_element_fewest"].get<long>() <=
          coverage["rays_per_element_median"].get<long>());
    CHECK(coverage["rays_per_element_median"].get<long>() <=
          coverage["rays_per_element_most"].get<long>());
    CHECK(coverage["elements_under_10_rays"].get<long>() <= 500);
    expect_error(riner_cli("reconstruct " + sim + "/sino.npy --set training.steps=-4 --out " +
                               (dir / "s").string(),
                           dir),
                 2, "config: training.steps must be in -1..10000000 (training steps; -1: the scan's, "
           "24000 in 2D and 12000 in 3D or more (min_draws_per_ray, min_samples_per_voxel))");
    expect_error(
        riner_cli("reconstruct " + sim + "/sino.npy --steps 0 --out " + (dir / "s").string(), dir),
        2,
        "training.steps is 0 and there is no warm start: the image would be the untrained field's "
        "noise; give 1 or more steps (-1: the scan's)");
    expect_error(riner_cli("reconstruct " + sim + "/sino.npy --set training.stepz=4 --out " +
                               (dir / "s").string(),
                           dir),
                 2, "config: unknown setting training.stepz (riner settings lists them)");
    expect_error(
        riner_cli("reconstruct " + sim + "/sino.npy --set steps --out " + (dir / "s").string(),
                  dir),
        2, "--set takes NAME=VALUE pairs separated by commas (got 'steps')");
  }

  TEST_CASE("reconstruct: the ring corrections change image and alpha by rings, or not at all") {
    riner::test::TempDir dir;
    const std::string sim = (dir / "sim").string();
    REQUIRE(riner_cli("simulate --quiet --seed 3 --out " + sim, dir).code == 0);
    // A short run at the full learning rate: the image is rough, but has rings to correct.
    // The readings' detail (detail.residual) held off: it is checked on its own below.
    riner::test::write_bytes(
        dir / "short.json",
        R"({"training": {"lr_decay_steps": 3000}, "detail": {"residual": false}})");
    const std::string common = "reconstruct " + sim +
                               "/sino.npy --steps 300 --seed 1 --json --config " +
                               (dir / "short.json").string() + " ";
    const Run with = riner_cli(common + "--format npy --out " + (dir / "a").string(), dir);
    const Run without =
        riner_cli(common + "--format npy --no-ring-correction --out " + (dir / "b").string(), dir);
    REQUIRE(with.code == 0);
    REQUIRE(without.code == 0);
    const auto rings = nlohmann::json::parse(with.out)["air_ring_correction"];
    CHECK(rings["applied"] == true);
    CHECK(rings["measured_radii"].get<int>() > 100);
    const auto gradient = nlohmann::json::parse(with.out)["gradient_ring_correction"];
    CHECK(gradient["measured_radii"].get<int>() > 100);
    CHECK(gradient["scale_px"] == 12.0);  // a 256² slice: the window of rings.gradient_scale_px 0
    CHECK(nlohmann::json::parse(without.out)["air_ring_correction"]["applied"] == false);
    CHECK(nlohmann::json::parse(without.out)["gradient_ring_correction"]["applied"] == false);
    const auto response = nlohmann::json::parse(with.out)["response_ring_correction"];
    CHECK(response["measured_radii"].get<int>() > 100);
    CHECK(nlohmann::json::parse(without.out)["response_ring_correction"]["applied"] == false);
    const auto again = nlohmann::json::parse(with.out)["gradient_after_response_ring_correction"];
    CHECK(again["measured_radii"].get<int>() > 100);
    // The quality report compares both with the same FBP.
    const auto q_with = nlohmann::json::parse(with.out)["quality"];
    const auto q_without = nlohmann::json::parse(without.out)["quality"];
    CHECK(q_with["fbp_ring_index"].get<double>() > 0.0);
    CHECK(q_with["fbp_ring_index"] == q_without["fbp_ring_index"]);
    CHECK(q_with["fbp_specks_per_10k_pixels"] == q_without["fbp_specks_per_10k_pixels"]);
    CHECK(std::isfinite(q_with["centre"]["fbp_noise_sigmas"].get<double>()));
    CHECK(q_with["fbp_edge_strength_per_mm"] == q_without["fbp_edge_strength_per_mm"]);
    CHECK(q_with["edge_strength_per_mm"].get<double>() > 0.0);
    // Training is deterministic, so the images differ by the subtracted rings alone: no pixel
    // by more than their largest values, and pixels at the same radius by the same amount.
    const riner::Array a = riner::read_array(dir / "a" / "image.npy").array;
    const riner::Array b = riner::read_array(dir / "b" / "image.npy").array;
    const double largest =
        rings["largest_ring_per_mm"].get<double>() +
        (gradient["applied"] == true ? gradient["largest_ring_per_mm"].get<double>() : 0.0) +
        (response["applied"] == true ? response["largest_ring_per_mm"].get<double>() : 0.0) +
        (again["applied"] == true ? again["largest_ring_per_mm"].get<double>() : 0.0);
    CHECK(largest > 0.0);
    double biggest_change = 0.0;
    for (std::size_t p = 0; p < a.size(); ++p) {
      biggest_change = std::max(biggest_change, std::fabs(double(a.data[p]) - b.data[p]));
    }
    CHECK(biggest_change > 0.5 * largest);
    CHECK(biggest_change <= largest * (1.0 + 1e-3));
    // The air training skipped (exactly 0 without the corrections) stays exactly 0.
    std::size_t skipped = 0;
    for (std::size_t p = 0; p < a.size(); ++p) {
      if (b.data[p] != 0.0f) continue;
      ++skipped;
      CHECK(a.data[p] == 0.0f);
    }
    CHECK(skipped > 10000);
    // Pixels (i, k), (k, 255 - i), (255 - i, 255 - k), (255 - k, i) lie on one circle; where
    // all four were trained, they changed alike. The difference of two float images is exact
    // to a few ulps of their values (~2e-9 at 0.02 / mm), hence the 1e-8 floor.
    for (std::size_t i = 0; i < 256; i += 7) {
      for (std::size_t k = 0; k < 256; k += 5) {
        if (b(i, k) == 0.0f || b(k, 255 - i) == 0.0f || b(255 - i, 255 - k) == 0.0f) continue;
        const float d = a(i, k) - b(i, k);
        CHECK(a(k, 255 - i) - b(k, 255 - i) == doctest::Approx(d).epsilon(1e-3).scale(1e-5));
        CHECK(a(255 - i, 255 - k) - b(255 - i, 255 - k) ==
              doctest::Approx(d).epsilon(1e-3).scale(1e-5));
      }
    }
    CHECK(riner::read_array(dir / "a" / "alpha.npy").array.data !=
          riner::read_array(dir / "b" / "alpha.npy").array.data);

    // With the readings' detail: the rough 300-step field gets it back, held out, and the
    // skipped air stays 0; --no-ring-correction leaves it off.
    const Run detail = riner_cli(
        common + "--set detail.residual=true --format npy --out " + (dir / "c").string(), dir);
    REQUIRE(detail.code == 0);
    const auto d = nlohmann::json::parse(detail.out)["residual_detail"];
    CHECK(d["applied"] == true);
    CHECK(d["consistent_share"].get<double>() >= 0.2);
    CHECK(d["misfit_after"].get<double>() < d["misfit_before"].get<double>());
    CHECK(d["rms_added"].get<double>() > 0.0);
    CHECK(nlohmann::json::parse(without.out)["residual_detail"]["applied"] == false);
    const riner::Array c = riner::read_array(dir / "c" / "image.npy").array;
    std::size_t changed = 0;
    for (std::size_t p = 0; p < c.size(); ++p) {
      if (a.data[p] == 0.0f) CHECK(c.data[p] == 0.0f);
      changed += c.data[p] != a.data[p];
    }
    CHECK(changed > c.size() / 4);

    // After the detail the gradient correction runs once more (rings.gradient_after_detail),
    // and only then. On this rough 300-step field the detail is large and the rings the step
    // finds would move the responses by more than the step's cap (3%): the image is kept.
    const auto after = nlohmann::json::parse(detail.out)["gradient_after_detail_ring_correction"];
    CHECK(after["measured_radii"].get<int>() > 100);
    CHECK(after["applied"] == false);
    CHECK(after["mean_response_change"].get<double>() > 0.03);
    // Without the detail the step does not run at all (no radii measured).
    CHECK_FALSE(nlohmann::json::parse(with.out)["gradient_after_detail_ring_correction"].contains(
        "measured_radii"));
    const std::string detail_on = common + "--set detail.residual=true --format npy ";
    const Run held = riner_cli(
        detail_on + "--set rings.gradient_after_detail=false --out " + (dir / "d").string(), dir);
    REQUIRE(held.code == 0);
    CHECK_FALSE(nlohmann::json::parse(held.out)["gradient_after_detail_ring_correction"].contains(
        "measured_radii"));
    const riner::Array e = riner::read_array(dir / "d" / "image.npy").array;
    CHECK(e.data == c.data);
    // With the cap raised it applies: image and alpha change by rings alone, the air stays 0.
    const Run raised = riner_cli(
        detail_on + "--set rings.gradient_max_mean_response_change=0.2 --out " +
            (dir / "e").string(),
        dir);
    const Run raised_held = riner_cli(detail_on +
                                          "--set rings.gradient_max_mean_response_change=0.2 "
                                          "--set rings.gradient_after_detail=false --out " +
                                          (dir / "f").string(),
                                      dir);
    REQUIRE(raised.code == 0);
    REQUIRE(raised_held.code == 0);
    CHECK(nlohmann::json::parse(raised.out)["gradient_after_detail_ring_correction"]["applied"] ==
          true);
    const riner::Array ringed = riner::read_array(dir / "e" / "image.npy").array;
    const riner::Array plain = riner::read_array(dir / "f" / "image.npy").array;
    std::size_t moved = 0;
    for (std::size_t p = 0; p < plain.size(); ++p) {
      if (plain.data[p] == 0.0f && a.data[p] == 0.0f) CHECK(ringed.data[p] == 0.0f);
      moved += ringed.data[p] != plain.data[p];
    }
    CHECK(moved > plain.size() / 4);
    for (std::size_t i = 0; i < 256; i += 7) {
      for (std::size_t k = 0; k < 256; k += 5) {
        if (plain(i, k) == 0.0f || plain(k, 255 - i) == 0.0f || plain(255 - i, 255 - k) == 0.0f)
          continue;
        const float step = ringed(i, k) - plain(i, k);
        CHECK(ringed(k, 255 - i) - plain(k, 255 - i) ==
              doctest::Approx(step).epsilon(1e-3).scale(1e-5));
        CHECK(ringed(255 - i, 255 - k) - plain(255 - i, 255 - k) ==
              doctest::Approx(step).epsilon(1e-3).scale(1e-5));
      }
    }
    CHECK(riner::read_array(dir / "e" / "alpha.npy").array.data !=
          riner::read_array(dir / "f" / "alpha.npy").array.data);
  }
}
