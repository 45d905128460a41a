// `riner reconstruct` by slabs: a run killed with SIGKILL and resumed equals an uninterrupted
// one, slice for slice and bit for bit; the output folder is never taken over unasked.
#include <doctest/doctest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <thread>
#include <utility>

#include "cli/cli_run.hpp"
#include "riner/cores.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "riner/volume_writer.hpp"
#include "support/fixture.hpp"

namespace {

using riner::test::Run;
using riner::test::riner_cli;

// A slab is done when its record, slabs/slab_NNNN.json, is there (written last).
std::size_t slabs_done(const std::filesystem::path& out) {
  std::size_t n = 0;
  for (std::size_t i = 0; i < 100; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "slabs/slab_%04zu.json", i);
    n += std::filesystem::exists(out / name);
  }
  return n;
}

void check_same_volume(const std::filesystem::path& a, const std::filesystem::path& b,
                       std::size_t slices) {
  for (std::size_t k = 0; k < slices; ++k) {
    char name[32];
    std::snprintf(name, sizeof(name), "volume/slice_%05zu.tif", k);
    CAPTURE(name);
    REQUIRE(std::filesystem::exists(b / name));
    CHECK(riner::test::read_bytes(a / name) == riner::test::read_bytes(b / name));
  }
  for (const char* name : {"alpha.npy", "beta.npy"}) {
    CHECK(riner::test::read_bytes(a / name) == riner::test::read_bytes(b / name));
  }
}

std::string simulate_stack(const riner::test::TempDir& dir) {
  return riner::test::simulate_small_parallel3d(dir) + "/sino.npy";
}

// The stack `scan` with detector row 7 reading NaN in every view, written as dir/dead/sino.npy
// beside its geometry; returned.
riner::Array stack_with_dead_row(const riner::test::TempDir& dir, const std::string& scan) {
  riner::Array views = riner::read_array(scan).array;
  const std::size_t rows = views.shape[1], columns = views.shape[2];
  for (std::size_t v = 0; v < views.shape[0]; ++v) {
    std::fill_n(views.data.begin() + static_cast<long>((v * rows + 7) * columns), columns, NAN);
  }
  std::filesystem::create_directories(dir / "dead");
  riner::write_array(dir / "dead" / "sino.npy", views);
  std::filesystem::copy_file(std::filesystem::path(scan).parent_path() / "geometry.json",
                             dir / "dead" / "geometry.json");
  return views;
}

std::size_t claims_left(const std::filesystem::path& out) {
  std::size_t claims = 0;
  for (const auto& entry : std::filesystem::directory_iterator(out / "slabs")) {
    claims += entry.path().extension() == ".claim";
  }
  return claims;
}

// The small stack in 5 slabs with `option` 1 (into dir/one) and 3 (into dir/three): the same
// volume byte for byte, every slab done; the second run's summary, and its run in `three`.
nlohmann::json one_against_three(const riner::test::TempDir& dir, const std::string& option,
                                 riner::test::Run* three) {
  const std::string common =
      "reconstruct " + simulate_stack(dir) + " --slab-slices 4 --steps 300 --quiet ";
  REQUIRE(riner_cli(common + option + " 1 --out " + (dir / "one").string(), dir).code == 0);
  *three = riner_cli(common + option + " 3 --out " + (dir / "three").string(), dir);
  CAPTURE(three->err);
  REQUIRE(three->code == 0);
  check_same_volume(dir / "one", dir / "three", 20);
  CHECK(slabs_done(dir / "three") == 5);
  const nlohmann::json summary =
      nlohmann::json::parse(riner::test::read_bytes(dir / "three" / "summary.json"));
  CHECK(summary["slabs"] == 5);
  CHECK(summary["per_slab"].size() == 5);
  return summary;
}

}  // namespace

TEST_SUITE("cli") {
  TEST_CASE("a slabbed run killed mid-way and resumed equals an uninterrupted one") {
    riner::test::TempDir dir;
    const std::string scan = simulate_stack(dir);
    const std::string common = "reconstruct " + scan + " --slab-slices 4 --steps 600 --quiet";
    const std::filesystem::path whole = dir / "whole", killed = dir / "killed";
    // --resume of a folder with no run says so, and starts one.
    const Run first = riner_cli(common + " --format h5 --resume --out " + whole.string(), dir);
    REQUIRE(first.code == 0);
    CHECK(first.err.find("--resume: " + whole.string() +
                         " holds no slabbed run (manifest.json): starting one") !=
          std::string::npos);
    const nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(whole / "summary.json"));
    CHECK(summary["slabs"] == 5);
    CHECK(summary["slabs_done_before"] == 0);
    // --format h5 gathers the slices into one dataset as well.
    CHECK(summary["volume_file"] == (whole / "volume.h5:/volume").string());
    const riner::Array gathered = riner::read_array((whole / "volume.h5:/volume").string()).array;
    const riner::Array slices = riner::read_array(whole / "volume").array;
    CHECK(gathered.shape == slices.shape);
    CHECK(gathered.data == slices.data);
    // --format nii given (the default's name) gathers too: before, it wrote no volume file.
    const std::filesystem::path nii = dir / "nii";
    REQUIRE(riner_cli("reconstruct " + scan +
                          " --slab-slices 10 --steps 20 --quiet --format nii --out " + nii.string(),
                      dir)
                .code == 0);
    const riner::Array nii_volume = riner::read_array(nii / "volume.nii").array;
    CHECK(nii_volume.data == riner::read_array(nii / "volume").array.data);
    // A finished run is no run to finish (it said "pass --resume to finish it").
    const Run again = riner_cli(
        "reconstruct " + scan + " --slab-slices 10 --steps 20 --quiet --out " + nii.string(), dir);
    CHECK(again.code != 0);
    CHECK(again.err.find("holds a finished slabbed run (manifest.json): choose another output "
                         "folder, or remove that folder to run again") != std::string::npos);

    // The same run, killed as soon as its first slab is written.
    riner::test::run_until({"reconstruct", scan, "--slab-slices", "4", "--steps", "600", "--quiet",
                            "--out", killed.string()},
                           [&] { return slabs_done(killed) > 0; });
    const std::size_t done = slabs_done(killed);
    CAPTURE(done);
    REQUIRE(done >= 1);
    REQUIRE(done < 5);  // killed mid-way, not after the end

    // Not taken over without --resume; not resumed with other settings.
    Run refused = riner_cli(common + " --out " + killed.string(), dir);
    CHECK(refused.code != 0);
    CHECK(refused.err.find("pass --resume") != std::string::npos);
    refused = riner_cli("reconstruct " + scan + " --slab-slices 4 --steps 500 --quiet --resume"
                        " --out " + killed.string(), dir);
    CHECK(refused.code != 0);
    CHECK(refused.err.find("another config") != std::string::npos);
    // The data is what must match, not its path: a copy elsewhere resumes; the same name with
    // other readings does not.
    const std::filesystem::path from = std::filesystem::path(scan).parent_path();
    for (const char* folder : {"moved", "changed"}) {
      std::filesystem::create_directories(dir / folder);
      std::filesystem::copy_file(scan, dir / folder / "sino.npy");
      std::filesystem::copy_file(from / "geometry.json", dir / folder / "geometry.json");
    }
    riner::Array readings = riner::read_array(scan).array;
    readings.data[readings.size() / 2] += 0.01f;
    riner::write_array(dir / "changed" / "sino.npy", readings);
    refused =
        riner_cli("reconstruct " + (dir / "changed" / "sino.npy").string() +
                      " --slab-slices 4 --steps 600 --quiet --resume --out " + killed.string(),
                  dir);
    CHECK(refused.code != 0);
    CHECK(refused.err.find("another data") != std::string::npos);

    const Run finished =
        riner_cli("reconstruct " + (dir / "moved" / "sino.npy").string() +
                      " --slab-slices 4 --steps 600 --quiet --resume --out " + killed.string(),
                  dir);
    REQUIRE(finished.code == 0);
    CHECK(finished.err.find("holds no slabbed run") == std::string::npos);
    const nlohmann::json resumed =
        nlohmann::json::parse(riner::test::read_bytes(killed / "summary.json"));
    CHECK(resumed["slabs_done_before"] == done);
    check_same_volume(whole, killed, 20);
    CHECK(resumed["per_slab"].size() == 5);
    // Nothing half-written left behind, nothing extra.
    std::size_t files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(killed / "volume")) {
      (void)entry;
      ++files;
    }
    CHECK(files == 20);
    const riner::Array alpha = riner::read_array(whole / "alpha.npy").array;
    CHECK(alpha.shape == std::vector<std::size_t>{20, 30});

    // A done slab's slice truncated since: --resume trains that slab again, and says so (its
    // record was trusted: the damaged file stayed, or every gather failed).
    const std::filesystem::path slice = killed / "volume" / "slice_00005.tif";
    std::filesystem::resize_file(slice, std::filesystem::file_size(slice) / 2);
    const Run mended = riner_cli(common + " --resume --out " + killed.string(), dir);
    REQUIRE(mended.code == 0);
    CHECK(mended.err.find("volume/slice_00005.tif is not the size slab 1's record gives") !=
          std::string::npos);
    check_same_volume(whole, killed, 20);
    // The manifest removed ("remove it to run again" read so): its slabs are not taken for a new
    // run's, whatever its settings (they were, a volume of other steps under this run's name).
    std::filesystem::remove(killed / "manifest.json");
    for (const char* resume : {"", " --resume"}) {
      const Run stale = riner_cli("reconstruct " + scan + " --slab-slices 4 --steps 300 --quiet" +
                                      resume + " --out " + killed.string(),
                                  dir);
      CHECK(stale.code != 0);
      CHECK(stale.err.find("holds a slabbed run's slabs (slabs/) but no manifest.json") !=
            std::string::npos);
    }
  }

  TEST_CASE("two and three MPI ranks share a slabbed run and give the volume of one") {
#ifdef RINER_TEST_MPI
    riner::test::TempDir dir;
    const std::string scan = simulate_stack(dir);
    const std::string common = " reconstruct " + scan + " --slab-slices 4 --steps 300 --quiet";
    const std::string mpirun = "mpirun --allow-run-as-root --oversubscribe -n ";
    const std::filesystem::path one = dir / "one", two = dir / "two", three = dir / "three";
    for (const auto& [ranks, out] :
         {std::pair<int, std::filesystem::path>{1, one}, {2, two}, {3, three}}) {
      const std::string command = mpirun + std::to_string(ranks) + " " + RINER_CLI_PATH + common +
                                  " --out " + out.string() + " >/dev/null 2>" +
                                  (dir / "stderr.txt").string();
      CAPTURE(command);
      const int status = std::system(command.c_str());
      CAPTURE(riner::test::read_bytes(dir / "stderr.txt"));
      REQUIRE(WIFEXITED(status));
      REQUIRE(WEXITSTATUS(status) == 0);
    }
    const nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(two / "summary.json"));
    CHECK(summary["ranks"] == 2);
    CHECK(summary["per_slab"].size() == 5);
    check_same_volume(one, two, 20);
    check_same_volume(one, three, 20);
    // Every slab has its record, and the claims are cleared away at the end.
    CHECK(slabs_done(two) == 5);
    CHECK(claims_left(two) == 0);

    // A run that is not slabbed is not done twice.
    const std::string whole = mpirun + "2 " + RINER_CLI_PATH + " reconstruct " + scan +
                              " --steps 10 --quiet --out " + (dir / "whole").string() +
                              " >/dev/null 2>" + (dir / "stderr.txt").string();
    const int status = std::system(whole.c_str());
    CHECK(!(WIFEXITED(status) && WEXITSTATUS(status) == 0));
    CHECK(riner::test::read_bytes(dir / "stderr.txt")
              .find("several processes share only a slabbed run") != std::string::npos);
#else
    MESSAGE("riner was built without MPI (libopenmpi-dev): nothing to test");
#endif
  }

  TEST_CASE("slabs trained several at once on one device give the volume of one at a time") {
    riner::test::TempDir dir;
    Run run;
    const nlohmann::json summary = one_against_three(dir, "--workers", &run);
    // On PoCL riner holds --workers to one (it says so): the test then checks the holding;
    // on another OpenCL device, the concurrency itself.
    const bool held = run.err.find("one at a time") != std::string::npos;
    CHECK(summary["workers"] == (held ? 1 : 3));
    CHECK(summary["slices_per_minute"].get<double>() > 0.0);
  }

  TEST_CASE("riner's own slab processes share a run and give the volume of one") {
    riner::test::TempDir dir;
    Run run;
    // Pinned (--pin) where the affinity mask holds a share of cores for each (not on 2 cores).
    const nlohmann::json summary = one_against_three(dir, "--pin --processes", &run);
    CHECK(summary["processes"] == 3);
    const int share = static_cast<int>(std::max(1u, riner::usable_cores() / 3));
    CHECK(summary["processes_pinned"] ==
          !riner::core_groups(riner::usable_core_ids(), 3, share).empty());
    CHECK(claims_left(dir / "three") == 0);  // cleared at the end
    // The machine's memory is every process's peak together.
    const nlohmann::json manifest =
        nlohmann::json::parse(riner::test::read_bytes(dir / "three" / "manifest.json"));
    std::map<std::string, std::size_t> process_peak;
    for (const nlohmann::json& slab : manifest["slabs"]) {
      std::size_t& p = process_peak[slab["process"].get<std::string>()];
      p = std::max(p, slab["peak_host_bytes"].get<std::size_t>());
    }
    std::size_t sum = 0;
    for (const auto& [process, peak] : process_peak) sum += peak;
    CHECK(summary["peak_host_bytes"].get<std::size_t>() == sum);
  }

  TEST_CASE("by slabs, the field's unit is said as a single scan's run says it") {
    // Voxels of 2^-10 mm (micrometres given as mm): the readings' attenuation per mm far from
    // the usual, the slabs' fields learn mu times a power of two. A slab run said nothing.
    riner::test::TempDir dir;
    const std::string sim = riner::test::simulate_small_parallel3d(dir);
    riner::test::write_bytes(dir / "um.json", R"({"type": "parallel3d",
        "detector": {"count": [30, 20], "pitch_mm": [0.0009765625, 0.0009765625]},
        "angles": {"count": 36, "range_rad": 3.141592653589793},
        "volume": {"shape": [20, 24, 24], "voxel_mm": 0.0009765625}})");
    const Run run =
        riner_cli("reconstruct " + sim + "/sino.npy --geometry " + (dir / "um.json").string() +
                      " --slab-slices 10 --steps 200 --out " + (dir / "out").string(),
                  dir);
    REQUIRE(run.code == 0);
    CHECK(run.out.find("the slabs' fields learn it times") != std::string::npos);
    const nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(dir / "out" / "summary.json"));
    REQUIRE(summary["field_per_mu"].size() == 1);
    CHECK(summary["field_per_mu"][0].get<double>() < 1.0);
  }

  TEST_CASE("slab options name their mistakes") {
    riner::test::TempDir dir;
    riner::test::write_bytes(dir / "geometry.json", R"({"type": "parallel2d",
        "detector": {"count": 8, "pitch_mm": 1.0},
        "angles": {"count": 6, "range_rad": 3.141592653589793},
        "volume": {"shape": [8, 8], "voxel_mm": 1.0}})");
    riner::write_array(dir / "sino.npy", riner::Array({6, 8}, 0.5f));
    Run run = riner_cli("reconstruct " + (dir / "sino.npy").string() + " --slab-slices 2 --out " +
                            (dir / "out").string(),
                        dir);
    CHECK(run.code != 0);
    CHECK(run.err.find("slabs of detector rows need a 3D geometry") != std::string::npos);
    run = riner_cli("reconstruct " + (dir / "sino.npy").string() + " --memory-limit lots --out " +
                        (dir / "out").string(),
                    dir);
    CHECK(run.code != 0);
    CHECK(run.err.find("a memory size is a number") != std::string::npos);
    run = riner_cli("reconstruct " + (dir / "sino.npy").string() + " --workers 0 --out " +
                        (dir / "out").string(),
                    dir);
    CHECK(run.code != 0);
    CHECK(run.err.find("--workers must be 1 to 256") != std::string::npos);
    run = riner_cli("reconstruct " + (dir / "sino.npy").string() + " --processes 0 --out " +
                        (dir / "out").string(),
                    dir);
    CHECK(run.code != 0);
    CHECK(run.err.find("--processes must be 1 to 1024") != std::string::npos);
  }

  TEST_CASE("a --memory-limit below one slice's slab is refused before anything is written") {
    // Before: a note, and the run went on at 268 MiB under a limit of 1 MiB.
    riner::test::TempDir dir;
    const std::string scan = simulate_stack(dir);
    for (const std::string command : {"reconstruct", "fbp"}) {
      CAPTURE(command);
      const std::filesystem::path out = dir / (command + "_out");
      const Run run =
          riner_cli(command + " " + scan + " --memory-limit 1M --out " + out.string(), dir);
      CHECK(run.code == 2);
      CHECK(run.err.find("--memory-limit 1M is less than a slab of one slice takes") !=
            std::string::npos);
      CHECK_FALSE(std::filesystem::exists(out));
    }
  }

  TEST_CASE("--slices-2d trains each slice as the 2D scan of its row, and resumes only so") {
    riner::test::TempDir dir;
    const std::string scan = simulate_stack(dir);  // one detector row per slice
    // The slab path plans the CPU gradient's sums for the whole machine; the 2D run is told
    // the same, so the two are the same computation.
    const std::string settings = " --steps 300 --set plan.gradient_slices=4 --quiet";
    const std::filesystem::path stack = dir / "stack";
    Run run = riner_cli("reconstruct " + scan + " --slices-2d" + settings + " --out " +
                            stack.string(),
                        dir);
    CAPTURE(run.err);
    REQUIRE(run.code == 0);
    const nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(stack / "summary.json"));
    CHECK(summary["slices_2d"] == true);
    CHECK(summary["slabs"] == 20);
    CHECK(summary["per_slab"][7]["trained_as"] == "slice_2d");
    CHECK(summary["per_slab"][7]["summary"]["shape"] == std::vector<int>{24, 24});
    CHECK(riner::read_array(stack / "alpha.npy").array.shape == std::vector<std::size_t>{20, 30});

    // Slice 7 on its own: row 7 of every view as a parallel2d scan.
    const riner::Array sino = riner::read_array(scan).array;  // [36, 20, 30]
    riner::Array row({36, 30});
    for (std::size_t a = 0; a < 36; ++a) {
      for (std::size_t u = 0; u < 30; ++u) row(a, u) = sino.data[(a * 20 + 7) * 30 + u];
    }
    std::filesystem::create_directories(dir / "row7");
    riner::write_array(dir / "row7" / "sino.npy", row);
    riner::test::write_bytes(dir / "row7" / "geometry.json", R"({"type": "parallel2d",
        "detector": {"count": 30, "pitch_mm": 1.0},
        "angles": {"count": 36, "range_rad": 3.141592653589793},
        "volume": {"shape": [24, 24], "voxel_mm": 1.0}})");
    run = riner_cli("reconstruct " + (dir / "row7" / "sino.npy").string() + settings +
                        " --format npy --out " + (dir / "alone").string(),
                    dir);
    CAPTURE(run.err);
    REQUIRE(run.code == 0);
    const riner::Array alone = riner::read_array(dir / "alone" / "image.npy").array;
    const riner::Array slice = riner::read_array(stack / "volume" / "slice_00007.tif").array;
    CHECK(slice.shape == alone.shape);
    CHECK(slice.data == alone.data);

    // The same rows under a 2D geometry (tooth.h5 beside its geometry.json) go the same way:
    // each row a slice of its own.
    std::filesystem::create_directories(dir / "rows2d");
    std::filesystem::copy_file(scan, dir / "rows2d" / "sino.npy");
    std::filesystem::copy_file(dir / "row7" / "geometry.json", dir / "rows2d" / "geometry.json");
    run = riner_cli("reconstruct " + (dir / "rows2d" / "sino.npy").string() + " --slices-2d" +
                        settings + " --out " + (dir / "rows2d_out").string(),
                    dir);
    CAPTURE(run.err);
    REQUIRE(run.code == 0);
    CHECK(riner::read_array(dir / "rows2d_out" / "volume" / "slice_00007.tif").array.data ==
          alone.data);

    // A slabbed run of this folder is resumed only as it was started.
    run = riner_cli("reconstruct " + scan + settings + " --resume --out " + stack.string(), dir);
    CHECK(run.code != 0);
    CHECK(run.err.find("another slices_2d") != std::string::npos);
    run = riner_cli("reconstruct " + scan + " --slices-2d --slab-slices 2 --out " +
                        (dir / "both").string(),
                    dir);
    CHECK(run.code != 0);
    CHECK(run.err.find("--slices-2d trains each slice alone") != std::string::npos);
  }

  TEST_CASE("a stack's partial rings: each slice's changing elements by row in the run's summary") {
    // 240 views of a 64 x 3 detector, 12 pixels changing and 3 dying part-way (riner simulate
    // --partial on a volume), each row trained as its 2D slice.
    riner::test::TempDir dir;
    riner::test::simulate_geometry(dir, "g.json", R"({"type": "parallel3d",
        "detector": {"count": [64, 3], "pitch_mm": [1.0, 1.0]},
        "angles": {"count": 240, "range_rad": 3.141592653589793},
        "volume": {"shape": [3, 48, 48], "voxel_mm": 1.0}})",
                                   "--seed 2 --partial 12 --partial-dead 3");
    const Run run = riner_cli("reconstruct " + (dir / "sim" / "sino.npy").string() +
                                  " --slices-2d --steps 20 --out " + (dir / "out").string(),
                              dir);
    CAPTURE(run.err);
    REQUIRE(run.code == 0);
    const nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(dir / "out" / "summary.json"));
    const nlohmann::json& changing = summary["changing_elements"];
    MESSAGE(changing.size() << " changing elements found of 15");
    REQUIRE(changing.size() >= 5);
    CHECK(run.out.find("partial rings: ") != std::string::npos);
    const riner::Array alpha = riner::read_array(dir / "sim" / "alpha.npy").array;  // [240, 3, 64]
    for (const nlohmann::json& c : changing) {
      const auto row = c["rows"][0].get<std::size_t>();
      const auto column = c["column"].get<std::size_t>();
      CAPTURE(row);
      CAPTURE(column);
      CHECK(c["rows"][1] == 1);
      // Found where the simulation changes that pixel's response, at its view.
      const auto first = c["segments"][1]["first_view"].get<std::size_t>();
      CHECK(alpha.data[(first * 3 + row) * 64 + column] !=
            alpha.data[((first - 1) * 3 + row) * 64 + column]);
    }
  }

  TEST_CASE("slices of 256 x 256 or more train alone in 2D by default; --field-3d keeps 3D slabs") {
    riner::test::TempDir dir;
    riner::test::simulate_geometry(dir, "g.json", R"({"type": "parallel3d",
        "detector": {"count": [260, 2], "pitch_mm": [1.0, 1.0]},
        "angles": {"count": 12, "range_rad": 3.141592653589793},
        "volume": {"shape": [2, 256, 256], "voxel_mm": 1.0}})",
                                   "--seed 2");
    const std::string scan = (dir / "sim" / "sino.npy").string();
    const std::string settings = " --steps 20 --quiet --out ";
    Run run = riner_cli("reconstruct " + scan + settings + (dir / "default").string(), dir);
    CAPTURE(run.err);
    REQUIRE(run.code == 0);
    nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(dir / "default" / "summary.json"));
    CHECK(summary["slices_2d"] == true);
    CHECK(summary["slabs"] == 2);
    CHECK(summary["per_slab"][1]["trained_as"] == "slice_2d");
    run = riner_cli("reconstruct " + scan + " --field-3d" + settings + (dir / "field").string(),
                    dir);
    CAPTURE(run.err);
    REQUIRE(run.code == 0);
    summary = nlohmann::json::parse(riner::test::read_bytes(dir / "field" / "summary.json"));
    CHECK(summary["slices_2d"] == false);
    CHECK(summary["per_slab"][0]["trained_as"] == "field_3d");
    run = riner_cli("reconstruct " + scan + " --field-3d --slices-2d" + settings +
                        (dir / "both").string(),
                    dir);
    CHECK(run.code == 2);
    CHECK(run.err.find("--slices-2d and --field-3d: choose one") != std::string::npos);
  }

  TEST_CASE("a cone beam by slabs: each slab trains the slices its rays cross, no seam") {
    // 60 views of a 40 x 40 detector at magnification 2 round a 24 x 20 x 20 volume: in slabs
    // of up to 8 slices, cut at the source's plane first (4 of 6), the outer slabs' rows climb
    // through slices beside their own.
    riner::test::TempDir dir;
    riner::test::simulate_geometry(dir, "g.json", R"({"type": "cone3d",
        "detector": {"count": [40, 40], "pitch_mm": [1.0, 1.0]},
        "source_origin_mm": 60, "origin_detector_mm": 60,
        "angles": {"count": 60, "range_rad": 6.283185307179586},
        "volume": {"shape": [24, 20, 20], "voxel_mm": 1.0}})",
                                   "--seed 4");
    const std::string scan = (dir / "sim" / "sino.npy").string();
    const std::string settings = " --steps 600 --format npy --quiet --out ";
    Run run = riner_cli("reconstruct " + scan + settings + (dir / "whole").string(), dir);
    CAPTURE(run.err);
    REQUIRE(run.code == 0);
    run = riner_cli(
        "reconstruct " + scan + " --slab-slices 8" + settings + (dir / "slabs").string(), dir);
    CAPTURE(run.err);
    REQUIRE(run.code == 0);
    CHECK(slabs_done(dir / "slabs") == 4);
    const nlohmann::json manifest =
        nlohmann::json::parse(riner::test::read_bytes(dir / "slabs" / "manifest.json"));
    // The outer slabs train slices beside their own; the detector's maps take each row once.
    CHECK(manifest["slabs"][0]["trained_slices"][1].get<int>() > 6);
    CHECK(manifest["slabs"][3]["trained_slices"][1].get<int>() > 6);
    std::size_t mapped = 0;
    for (const auto& slab : manifest["slabs"]) {
      // Absent where a slab maps every row it reads.
      mapped += slab.value("map_rows", slab["rows"])[1].get<std::size_t>();
    }
    CHECK(mapped == 40);
    // A dead element read by two slabs is listed once, as the whole volume's run lists it.
    const nlohmann::json whole_summary =
        nlohmann::json::parse(riner::test::read_bytes(dir / "whole" / "summary.json"));
    const nlohmann::json slabs_summary =
        nlohmann::json::parse(riner::test::read_bytes(dir / "slabs" / "summary.json"));
    CHECK(slabs_summary["dead_elements"] == whole_summary["dead_elements"].size());
    const riner::Array alpha = riner::read_array(dir / "slabs" / "alpha.npy").array;
    CHECK(
        std::none_of(alpha.data.begin(), alpha.data.end(), [](float a) { return std::isnan(a); }));

    const riner::Array truth = riner::read_array(dir / "sim" / "ground_truth.nii").array;
    const riner::Array whole = riner::read_array(dir / "whole" / "image.npy").array;
    const riner::Array slabs = riner::read_array(dir / "slabs" / "volume.npy").array;
    REQUIRE(slabs.shape == truth.shape);
    const double whole_psnr = riner::psnr(whole, truth), slabs_psnr = riner::psnr(slabs, truth);
    MESSAGE("cone beam, 600 steps: whole " << whole_psnr << " dB, 4 slabs " << slabs_psnr);
    CHECK(slabs_psnr > whole_psnr - 1.0);
    // No seam: the slices at the slabs' borders are as close to the truth as the others.
    auto slice_error = [&](std::size_t k) {
      double sum = 0.0;
      for (std::size_t i = 0; i < 400; ++i) {
        const double d = slabs.data[k * 400 + i] - truth.data[k * 400 + i];
        sum += d * d;
      }
      return std::sqrt(sum / 400.0);
    };
    double inner = 0.0;
    for (std::size_t k : {2, 3, 8, 9, 14, 15, 20, 21}) inner = std::max(inner, slice_error(k));
    for (std::size_t k : {5, 6, 11, 12, 17, 18}) {
      CAPTURE(k);
      CHECK(slice_error(k) < 1.5 * inner);
    }

#ifdef RINER_TEST_MPI
    // Two ranks share the cone slabs (each with its padding slices and rows) and write the
    // volume and maps of one process, byte for byte.
    const std::string ranks = "mpirun --allow-run-as-root --oversubscribe -n 2 " +
                              std::string(RINER_CLI_PATH) + " reconstruct " + scan +
                              " --slab-slices 8" + settings + (dir / "ranks").string() +
                              " >/dev/null 2>" + (dir / "stderr.txt").string();
    CAPTURE(ranks);
    const int status = std::system(ranks.c_str());
    CAPTURE(riner::test::read_bytes(dir / "stderr.txt"));
    REQUIRE(WIFEXITED(status));
    REQUIRE(WEXITSTATUS(status) == 0);
    CHECK(slabs_done(dir / "ranks") == 4);
    for (const char* name : {"volume.npy", "alpha.npy", "beta.npy"}) {
      CAPTURE(name);
      CHECK(riner::test::read_bytes(dir / "slabs" / name) ==
            riner::test::read_bytes(dir / "ranks" / name));
    }
#endif
  }

  TEST_CASE("riner fbp by slabs writes the whole volume's slices, into a folder or an HDF5 file") {
    riner::test::TempDir dir;
    const std::string scan = simulate_stack(dir);
    REQUIRE(riner_cli("fbp " + scan + " --quiet --out " + (dir / "whole.npy").string(), dir).code ==
            0);
    const riner::Array whole = riner::read_array((dir / "whole.npy").string()).array;
    Run run = riner_cli("fbp " + scan + " --slab-slices 3 --json --out " +
                            (dir / "vol.h5:/entry/recon").string(),
                        dir);
    REQUIRE(run.code == 0);
    const nlohmann::json summary = nlohmann::json::parse(run.out);
    CHECK(summary["slabs"] == 7);
    run = riner_cli("fbp " + scan + " --slab-slices 8 --quiet --png --out " +
                        (dir / "slices").string(),
                    dir);
    REQUIRE(run.code == 0);
    CHECK(std::filesystem::exists(dir / "slices" / "middle_slice.png"));
    for (const std::string& volume :
         {(dir / "vol.h5:/entry/recon").string(), (dir / "slices").string()}) {
      CAPTURE(volume);
      const riner::Array slabbed = riner::read_array(volume).array;
      REQUIRE(slabbed.shape == whole.shape);
      float worst = 0.0f;
      for (std::size_t i = 0; i < whole.size(); ++i) {
        worst = std::max(worst, std::fabs(slabbed.data[i] - whole.data[i]));
      }
      CHECK(worst < 1e-5f);
    }
    // A folder that already holds a volume is not written over.
    run = riner_cli("fbp " + scan + " --slab-slices 8 --quiet --out " + (dir / "slices").string(),
                    dir);
    CHECK(run.code != 0);
    CHECK(run.err.find("already holds slices") != std::string::npos);
    run = riner_cli("fbp " + scan + " --slab-slices 0 --out " + (dir / "z").string(), dir);
    CHECK(run.code != 0);
    CHECK(run.err.find("--slab-slices must be 1 or more") != std::string::npos);
  }

  TEST_CASE("by slabs, raw projections are reported as a whole scan's: normalisation, drift") {
    // The beam fades 10% over the views: the flat from before the scan no longer fits.
    riner::test::TempDir dir;
    const std::string scan = simulate_stack(dir);
    const std::string geometry = (std::filesystem::path(scan).parent_path() / "geometry.json");
    riner::Array intensities = riner::read_array(scan).array;
    const std::size_t views = intensities.shape[0];
    const std::size_t per_view = intensities.size() / views;
    for (std::size_t i = 0; i < intensities.size(); ++i) {
      const float fade = 1.0f - 0.1f * static_cast<float>(i / per_view) / (views - 1.0f);
      const float v = intensities.data[i];
      intensities.data[i] = std::isfinite(v) ? 1000.0f * fade * std::exp(-v) : 0.0f;
    }
    riner::write_array(dir / "raw.npy", intensities);
    riner::write_array(dir / "flats.npy",
                       riner::Array({2, intensities.shape[1], intensities.shape[2]}, 1000.0f));
    const std::string raw = (dir / "raw.npy").string() + " --flat " + (dir / "flats.npy").string() +
                            " --geometry " + geometry;
    Run run =
        riner_cli("reconstruct " + raw + " --steps 100 --out " + (dir / "whole").string(), dir);
    REQUIRE(run.code == 0);
    run = riner_cli(
        "reconstruct " + raw + " --slab-slices 4 --steps 100 --out " + (dir / "slabs").string(),
        dir);
    CAPTURE(run.out);
    REQUIRE(run.code == 0);
    CHECK(run.out.find("raw projections: flat field of 2 frame(s)") != std::string::npos);
    CHECK(run.out.find("the beam or the detector drifted during the scan") != std::string::npos);
    const nlohmann::json whole =
        nlohmann::json::parse(riner::test::read_bytes(dir / "whole" / "summary.json"));
    const nlohmann::json slabs =
        nlohmann::json::parse(riner::test::read_bytes(dir / "slabs" / "summary.json"));
    REQUIRE(slabs["flat_field"].is_object());
    CHECK(slabs["flat_field"]["air_drifts"] == true);
    CHECK(slabs["flat_field"]["invalid_readings"] == whole["flat_field"]["invalid_readings"]);
    CHECK(slabs["non_finite_measurements"] == whole["non_finite_measurements"]);
    run =
        riner_cli("fbp " + raw + " --slab-slices 4 --json --out " + (dir / "f.npy").string(), dir);
    REQUIRE(run.code == 0);
    const nlohmann::json fbp = nlohmann::json::parse(run.out);
    REQUIRE(fbp["flat_field"].is_object());
    CHECK(fbp["flat_field"]["air_drifts"] == true);
    CHECK(fbp["flat_field"]["invalid_readings"] == whole["flat_field"]["invalid_readings"]);
  }

  TEST_CASE("a dead detector row in a volume trained as one field: filled from its neighbours") {
    // Its slice is seen by no ray: the field read there what it never learnt (a simulated cone
    // head's slice 0.0009 against its 0.0100, 14.4 dB among neighbours at 27-30), unsaid.
    riner::test::TempDir dir;
    const std::string scan = simulate_stack(dir);
    const riner::Array views = stack_with_dead_row(dir, scan);
    const std::size_t columns = views.shape[2];
    const std::filesystem::path sim = std::filesystem::path(scan).parent_path();
    const riner::Array truth = riner::read_array(sim / "ground_truth.nii").array;
    for (const std::string mode : {"whole", "slabs"}) {
      CAPTURE(mode);
      const std::filesystem::path out = dir / mode;
      const Run run =
          riner_cli("reconstruct " + (dir / "dead" / "sino.npy").string() + " --steps 2000 --out " +
                        out.string() + (mode == "slabs" ? " --field-3d --slab-slices 5" : ""),
                    dir);
      CAPTURE(run.err);
      REQUIRE(run.code == 0);
      CHECK(run.out.find("note: detector row 7 read nothing in any view: trained on the line "
                         "between the rows beside them") != std::string::npos);
      riner::Array image;
      if (mode == "whole") {
        image = riner::read_array(out / "image.nii").array;
        const nlohmann::json summary =
            nlohmann::json::parse(riner::test::read_bytes(out / "summary.json"));
        CHECK(summary["filled_rows"] == nlohmann::json({7}));
      } else {
        image = truth;
        for (std::size_t k = 0; k < truth.shape[0]; ++k) {
          const riner::Array slice =
              riner::read_array(riner::VolumeWriter::slice_file(out / "volume", k)).array;
          std::copy(slice.data.begin(), slice.data.end(),
                    image.data.begin() + static_cast<long>(k * slice.size()));
        }
      }
      const auto rms_off = [&](std::size_t k) {
        const std::size_t n = truth.shape[1] * truth.shape[2];
        double sum = 0.0;
        for (std::size_t i = k * n; i < (k + 1) * n; ++i) {
          sum += (image.data[i] - truth.data[i]) * (image.data[i] - truth.data[i]);
        }
        return std::sqrt(sum / static_cast<double>(n));
      };
      const auto mean = [&](const riner::Array& a, std::size_t k) {
        const std::size_t n = a.shape[1] * a.shape[2];
        double sum = 0.0;
        for (std::size_t i = k * n; i < (k + 1) * n; ++i) sum += a.data[i];
        return sum / static_cast<double>(n);
      };
      // Before: slice 7 read 0.0005 for its 0.0114, 0.0179 rms off against its neighbours' 0.0085
      // and 0.0101; now 0.0107, 0.0097.
      CHECK(std::fabs(mean(image, 7) - mean(truth, 7)) < 0.2 * mean(truth, 7));
      CHECK(rms_off(7) < 1.3 * std::max(rms_off(6), rms_off(8)));
      const riner::Array beta = riner::read_array(out / "beta.npy").array;
      CHECK(beta.data[7 * columns] == 0.0f);  // its elements are dead all the same
    }
  }

  TEST_CASE("a dead detector row: its slice is NaN and said so, the rest of the scan goes on") {
    riner::test::TempDir dir;
    const std::string scan = simulate_stack(dir);
    riner::Array views = stack_with_dead_row(dir, scan);
    const std::size_t rows = views.shape[1], columns = views.shape[2];
    // Each slice trained as its row's 2D scan: row 7 has nothing (it stopped the run before).
    const Run run = riner_cli("reconstruct " + (dir / "dead" / "sino.npy").string() +
                                  " --slices-2d --steps 100 --out " + (dir / "out").string(),
                              dir);
    CAPTURE(run.err);
    REQUIRE(run.code == 0);
    CHECK(run.out.find("slice 7 written as NaN: detector row 7 read nothing to reconstruct") !=
          std::string::npos);
    const nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(dir / "out" / "summary.json"));
    REQUIRE(summary["slabs_without_readings"].size() == 1);
    CHECK(summary["slabs_without_readings"][0]["slices"] == nlohmann::json({7, 1}));
    for (std::size_t k : {6, 7, 8}) {
      CAPTURE(k);
      const riner::Array slice =
          riner::read_array(riner::VolumeWriter::slice_file(dir / "out" / "volume", k)).array;
      std::size_t finite = 0;
      for (float v : slice.data) finite += std::isfinite(v) ? 1 : 0;
      CHECK(finite == (k == 7 ? 0 : slice.size()));
    }
    const riner::Array beta = riner::read_array(dir / "out" / "beta.npy").array;
    CHECK(beta.data[7 * columns] == 0.0f);
    // fbp by slabs of one slice reads each slice's row and two rows either side: with rows
    // 4-13 dead, slices 6-11 read nothing (the run stopped at the first of them).
    for (std::size_t v = 0; v < views.shape[0]; ++v) {
      std::fill_n(views.data.begin() + static_cast<long>((v * rows + 4) * columns), 10 * columns,
                  NAN);
    }
    riner::write_array(dir / "dead" / "block.npy", views);
    const Run fbp = riner_cli("fbp " + (dir / "dead" / "block.npy").string() + " --geometry " +
                                  (dir / "dead" / "geometry.json").string() +
                                  " --slab-slices 1 --json --out " + (dir / "fbp").string(),
                              dir);
    CAPTURE(fbp.err);
    REQUIRE(fbp.code == 0);
    CHECK(nlohmann::json::parse(fbp.out)["slices_without_readings"] == 6);
    for (std::size_t k = 3; k < 15; ++k) {
      CAPTURE(k);
      const riner::Array slice =
          riner::read_array(riner::VolumeWriter::slice_file(dir / "fbp", k)).array;
      const bool nan =
          std::all_of(slice.data.begin(), slice.data.end(), [](float v) { return std::isnan(v); });
      CHECK(nan == (k >= 6 && k <= 11));
    }
  }

  TEST_CASE("by slabs, inputs checked before the first slab: no output replaces one, flats fit") {
    // Slabs read their rows late; the outputs are opened first.
    riner::test::TempDir dir;
    const std::string scan = simulate_stack(dir);
    const std::string geometry = (std::filesystem::path(scan).parent_path() / "geometry.json");
    const std::string before = riner::test::read_bytes(scan);
    Run run = riner_cli("fbp " + scan + " --slab-slices 4 --out " + scan, dir);
    CHECK(run.code == 2);
    CHECK(run.err.find(scan + ": refusing to overwrite an input file") != std::string::npos);
    CHECK(riner::test::read_bytes(scan) == before);
    // The stack as a folder of one TIFF per view, and slices asked into that folder.
    const riner::Array views = riner::read_array(scan).array;
    const std::size_t rows = views.shape[1], columns = views.shape[2];
    std::filesystem::create_directories(dir / "tifs");
    for (std::size_t v = 0; v < views.shape[0]; ++v) {
      riner::Array view({rows, columns});
      std::copy_n(views.data.begin() + static_cast<long>(v * rows * columns), rows * columns,
                  view.data.begin());
      char name[32];
      std::snprintf(name, sizeof(name), "proj_%03zu.tif", v);
      riner::write_array(dir / "tifs" / name, view);
    }
    run = riner_cli("fbp " + (dir / "tifs").string() + " --geometry " + geometry +
                        " --slab-slices 4 --out " + (dir / "tifs").string(),
                    dir);
    CHECK(run.code == 2);
    CHECK(run.err.find("refusing to overwrite an input file") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(riner::VolumeWriter::slice_file(dir / "tifs", 0)));
    // `info` of a folder read as a stack (before: "unknown file type ''").
    CHECK(riner_cli("info --quiet " + (dir / "tifs").string(), dir).code == 0);
    // One field for the whole stack into its own folder (before: image.tif written among the
    // projections, which then no longer read as a stack).
    run = riner_cli("reconstruct " + (dir / "tifs").string() + " --geometry " + geometry +
                        " --field-3d --steps 20 --format tif --out " + (dir / "tifs").string(),
                    dir);
    CHECK(run.code == 2);
    CHECK(run.err.find("tifs: refusing to overwrite an input file") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(dir / "tifs" / "image.tif"));
    // reconstruct's gathered volume file: refused before any slab is trained.
    std::filesystem::create_directories(dir / "held");
    std::filesystem::copy_file(scan, dir / "held" / "volume.npy");
    run = riner_cli("reconstruct " + (dir / "held" / "volume.npy").string() + " --geometry " +
                        geometry + " --slab-slices 4 --format npy --out " + (dir / "held").string(),
                    dir);
    CHECK(run.code == 2);
    CHECK(run.err.find("volume.npy: refusing to overwrite an input file") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(dir / "held" / "slabs"));
    // Flats of another detector: refused before the first slab (they were read a slab's rows
    // at a time: too many rows passed, too few failed after slabs were written).
    riner::Array intensities = riner::read_array(scan).array;
    for (float& v : intensities.data) v = std::isfinite(v) ? 1000.0f * std::exp(-v) : 0.0f;
    riner::write_array(dir / "raw.npy", intensities);
    for (const std::size_t rows : {intensities.shape[1] + 2, intensities.shape[1] - 2}) {
      CAPTURE(rows);
      riner::write_array(dir / "flats.npy", riner::Array({2, rows, intensities.shape[2]}, 1000.0f));
      run = riner_cli("reconstruct " + (dir / "raw.npy").string() + " --flat " +
                          (dir / "flats.npy").string() + " --geometry " + geometry +
                          " --slab-slices 4 --out " + (dir / "flat").string(),
                      dir);
      CHECK(run.code == 2);
      CHECK(run.err.find("flats.npy: the flat field of shape [2, " + std::to_string(rows) +
                         ", 30] is neither one frame of a view's shape [20, 30]") !=
            std::string::npos);
      CHECK_FALSE(std::filesystem::exists(dir / "flat" / "slabs"));
    }
    // A single scan's run into a slabbed run's folder would mix the two runs' outputs.
    riner::test::write_bytes(dir / "held" / "manifest.json", "{}");
    run = riner_cli("reconstruct " + scan + " --out " + (dir / "held").string(), dir);
    CHECK(run.code != 0);
    CHECK(run.err.find("the folder holds a slabbed run") != std::string::npos);
  }
}
