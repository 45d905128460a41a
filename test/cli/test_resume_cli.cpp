// `riner reconstruct` of a slice, or of a stack by slabs, killed with SIGKILL mid-training and
// started again with --resume goes on from its checkpoint to the uninterrupted run's bits; the
// checkpoint is never overwritten unasked, nor taken up by other settings.
#include <doctest/doctest.h>

#include <sys/wait.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli/cli_run.hpp"
#include "riner/io.hpp"
#include "support/fixture.hpp"

using riner::test::riner_cli;
using riner::test::Run;
using riner::test::run_until;

TEST_SUITE("cli") {
  TEST_CASE("a slice's training killed mid-way and resumed from its checkpoint equals one run") {
    riner::test::TempDir dir;
    const std::string sim = riner::test::simulate_small_parallel2d(dir, 4);
    const std::string common = "reconstruct " + sim + "/sino.npy --geometry " + sim +
                               "/geometry.json --steps 4000 --quiet";
    const std::filesystem::path whole = dir / "whole", killed = dir / "killed";
    REQUIRE(riner_cli(common + " --out " + whole.string(), dir).code == 0);
    CHECK(!std::filesystem::exists(whole / "training.checkpoint"));

    // The same run saving every 0.3 s of training, killed once the first checkpoint is there.
    const std::filesystem::path checkpoint = killed / "training.checkpoint";
    run_until({"reconstruct", sim + "/sino.npy", "--geometry", sim + "/geometry.json", "--steps",
               "4000", "--quiet", "--checkpoint-minutes", "0.005", "--out", killed.string()},
              [&] { return std::filesystem::exists(checkpoint); });
    REQUIRE(std::filesystem::exists(checkpoint));
    REQUIRE(!std::filesystem::exists(killed / "image.nii"));  // killed before the end

    // Not overwritten without --resume; not taken up with other settings.
    Run refused = riner_cli(common + " --out " + killed.string(), dir);
    CHECK(refused.code != 0);
    CHECK(refused.err.find("holds an unfinished training: --resume goes on from it") !=
          std::string::npos);
    refused = riner_cli("reconstruct " + sim + "/sino.npy --geometry " + sim +
                            "/geometry.json --steps 3000 --quiet --resume --out " + killed.string(),
                        dir);
    CHECK(refused.code != 0);
    CHECK(refused.err.find("a checkpoint of other settings") != std::string::npos);
    CHECK(std::filesystem::exists(checkpoint));

    const Run finished = riner_cli(common + " --resume --out " + killed.string(), dir);
    REQUIRE(finished.code == 0);
    const nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(killed / "summary.json"));
    CAPTURE(summary["resumed_at_step"]);
    CHECK(summary["resumed_at_step"] > 0);
    CHECK(summary["resumed_at_step"] < 4000);
    CHECK(summary["steps"] == 4000);
    for (const char* file : {"image.nii", "alpha.npy", "beta.npy", "loss.csv"}) {
      CAPTURE(file);
      CHECK(riner::test::read_bytes(killed / file) == riner::test::read_bytes(whole / file));
    }
    CHECK(!std::filesystem::exists(checkpoint));  // a finished run's outputs stand for it

    // --resume with no checkpoint says so and trains from the start.
    const Run fresh =
        riner_cli("reconstruct " + sim + "/sino.npy --geometry " + sim +
                      "/geometry.json --steps 4000 --resume --out " + (dir / "fresh").string(),
                  dir);
    REQUIRE(fresh.code == 0);
    CHECK(fresh.out.find("--resume: no training.checkpoint in") != std::string::npos);
    CHECK(riner::test::read_bytes(dir / "fresh" / "image.nii") ==
          riner::test::read_bytes(whole / "image.nii"));
  }

  TEST_CASE("a slabbed run killed mid-slab goes on from the slab's checkpoint") {
    riner::test::TempDir dir;
    const std::string sim = riner::test::simulate_small_parallel3d(dir);
    const std::string common = "reconstruct " + sim + "/sino.npy --geometry " + sim +
                               "/geometry.json --slab-slices 10 --steps 1500 --quiet";
    const std::filesystem::path whole = dir / "whole", killed = dir / "killed";
    REQUIRE(riner_cli(common + " --out " + whole.string(), dir).code == 0);

    const std::filesystem::path checkpoint = killed / "slabs" / "slab_0000.checkpoint";
    run_until({"reconstruct", sim + "/sino.npy", "--geometry", sim + "/geometry.json",
               "--slab-slices", "10", "--steps", "1500", "--quiet", "--checkpoint-minutes", "0.003",
               "--out", killed.string()},
              [&] { return std::filesystem::exists(checkpoint); });
    REQUIRE(std::filesystem::exists(checkpoint));
    REQUIRE(!std::filesystem::exists(killed / "slabs" / "slab_0000.json"));  // mid-slab

    const Run finished = riner_cli(common + " --resume --out " + killed.string(), dir);
    REQUIRE(finished.code == 0);
    const nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(killed / "summary.json"));
    REQUIRE(summary["per_slab"].size() == 2);
    const nlohmann::json first = summary["per_slab"][0]["summary"]["resumed_at_step"];
    CAPTURE(first);
    CHECK(first > 0);
    CHECK(first < 1500);
    CHECK(summary["per_slab"][1]["summary"]["resumed_at_step"].is_null());
    CHECK(riner::read_array(killed / "volume").array.data ==
          riner::read_array(whole / "volume").array.data);
    CHECK(riner::test::read_bytes(killed / "alpha.npy") ==
          riner::test::read_bytes(whole / "alpha.npy"));
    CHECK(!std::filesystem::exists(checkpoint));
  }

  TEST_CASE("SIGTERM mid-training saves the checkpoint and exits 143; --resume goes on from it") {
    riner::test::TempDir dir;
    const std::string sim = riner::test::simulate_small_parallel2d(dir, 5);
    const std::string common = "reconstruct " + sim + "/sino.npy --geometry " + sim +
                               "/geometry.json --steps 5000 --quiet";
    const std::filesystem::path whole = dir / "whole", stopped = dir / "stopped";
    REQUIRE(riner_cli(common + " --out " + whole.string(), dir).code == 0);

    // SIGTERM once training is under way (its first periodic checkpoint is there).
    const int status = run_until(
        {"reconstruct", sim + "/sino.npy", "--geometry", sim + "/geometry.json", "--steps", "5000",
         "--quiet", "--checkpoint-minutes", "0.002", "--out", stopped.string()},
        [&] { return std::filesystem::exists(stopped / "training.checkpoint"); }, SIGTERM);
    REQUIRE(WIFEXITED(status));
    CHECK(WEXITSTATUS(status) == 128 + SIGTERM);
    REQUIRE(std::filesystem::exists(stopped / "training.checkpoint"));
    CHECK(!std::filesystem::exists(stopped / "image.nii"));

    const Run finished = riner_cli(common + " --resume --out " + stopped.string(), dir);
    REQUIRE(finished.code == 0);
    const nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(stopped / "summary.json"));
    CAPTURE(summary["resumed_at_step"]);
    CHECK(summary["resumed_at_step"] > 0);
    CHECK(riner::test::read_bytes(stopped / "image.nii") ==
          riner::test::read_bytes(whole / "image.nii"));
  }
}
