// `riner reconstruct` of a slice, or of a stack by slabs, killed with SIGKILL mid-training and
// started again with --resume goes on from its checkpoint to the uninterrupted run's bits; the
// checkpoint is never overwritten unasked, nor taken up by other settings. SIGTERM saves it and
// stops, by riner alone or through mpirun; one during a write leaves no half-written file.
#include <doctest/doctest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <optional>
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
    // While it trains, the same command again (--resume, as a requeued job would) is refused:
    // it would overwrite the live run's checkpoint and outputs.
    std::optional<Run> beside;
    run_until({"reconstruct", sim + "/sino.npy", "--geometry", sim + "/geometry.json", "--steps",
               "4000", "--quiet", "--checkpoint-minutes", "0.005", "--out", killed.string()},
              [&] {
                if (!std::filesystem::exists(checkpoint)) return false;
                beside = riner_cli(common + " --resume --out " + killed.string(), dir);
                return true;
              });
    REQUIRE(std::filesystem::exists(checkpoint));
    REQUIRE(!std::filesystem::exists(killed / "image.nii"));  // killed before the end
    REQUIRE(beside);
    CHECK(beside->code != 0);
    CHECK(beside->err.find("another riner run") != std::string::npos);

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

  TEST_CASE("a volume trained whole, killed mid-way, resumes from its checkpoint, not by slabs") {
    // --resume on a 3D scan went to the slabs' scheduler whatever the folder held: a volume
    // trained whole started again from step 0 as one slab (no image.nii), and its checkpoint
    // stayed, refusing every plain run after.
    riner::test::TempDir dir;
    const std::string sim = riner::test::simulate_small_parallel3d(dir);
    const std::string common = "reconstruct " + sim + "/sino.npy --geometry " + sim +
                               "/geometry.json --steps 3000 --quiet";
    const std::filesystem::path whole = dir / "whole", killed = dir / "killed";
    REQUIRE(riner_cli(common + " --out " + whole.string(), dir).code == 0);
    const std::filesystem::path checkpoint = killed / "training.checkpoint";
    run_until({"reconstruct", sim + "/sino.npy", "--geometry", sim + "/geometry.json", "--steps",
               "3000", "--quiet", "--checkpoint-minutes", "0.003", "--out", killed.string()},
              [&] { return std::filesystem::exists(checkpoint); });
    REQUIRE(std::filesystem::exists(checkpoint));
    REQUIRE(!std::filesystem::exists(killed / "image.nii"));
    const Run finished = riner_cli(common + " --resume --out " + killed.string(), dir);
    REQUIRE(finished.code == 0);
    const nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(killed / "summary.json"));
    CAPTURE(summary["resumed_at_step"]);
    CHECK(summary["resumed_at_step"] > 0);
    CHECK(!std::filesystem::exists(killed / "manifest.json"));
    CHECK(!std::filesystem::exists(checkpoint));
    CHECK(riner::test::read_bytes(killed / "image.nii") ==
          riner::test::read_bytes(whole / "image.nii"));
    // --resume on a fresh folder trains the volume as a plain run would.
    const Run fresh = riner_cli(common + " --resume --out " + (dir / "fresh").string(), dir);
    REQUIRE(fresh.code == 0);
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
    // A second run on the folder while the first trains would train every slab again beside it.
    std::optional<Run> beside;
    run_until({"reconstruct", sim + "/sino.npy", "--geometry", sim + "/geometry.json",
               "--slab-slices", "10", "--steps", "1500", "--quiet", "--checkpoint-minutes", "0.003",
               "--out", killed.string()},
              [&] {
                if (!std::filesystem::exists(checkpoint)) return false;
                beside = riner_cli(common + " --resume --out " + killed.string(), dir);
                return true;
              });
    REQUIRE(std::filesystem::exists(checkpoint));
    REQUIRE(!std::filesystem::exists(killed / "slabs" / "slab_0000.json"));  // mid-slab
    REQUIRE(beside);
    CHECK(beside->code != 0);
    CHECK(beside->err.find("another riner run") != std::string::npos);
    // What a SIGKILL mid-write would leave.
    const std::filesystem::path half_written =
        killed / "slabs" /
        ("slab_0000.checkpoint" + riner::temporary_marker(riner::test::ended_process_id()) + "1.0");
    riner::test::write_bytes(half_written, "partial");

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
    CHECK(!std::filesystem::exists(half_written));
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

    // A byte flipped in the checkpoint (a disk's damage): refused by name, not trained on.
    const std::string saved = riner::test::read_bytes(stopped / "training.checkpoint");
    std::string damaged = saved;
    damaged[damaged.size() / 2] = static_cast<char>(~damaged[damaged.size() / 2]);
    riner::test::write_bytes(stopped / "training.checkpoint", damaged);
    const Run refused = riner_cli(common + " --resume --out " + stopped.string(), dir);
    CHECK(refused.code != 0);
    CHECK(refused.err.find("training.checkpoint: truncated or corrupt (its checksum does not "
                           "match its bytes)") != std::string::npos);
    CHECK(riner::test::read_bytes(stopped / "training.checkpoint") == damaged);
    riner::test::write_bytes(stopped / "training.checkpoint", saved);

    const Run finished = riner_cli(common + " --resume --out " + stopped.string(), dir);
    REQUIRE(finished.code == 0);
    const nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(stopped / "summary.json"));
    CAPTURE(summary["resumed_at_step"]);
    CHECK(summary["resumed_at_step"] > 0);
    CHECK(riner::test::read_bytes(stopped / "image.nii") ==
          riner::test::read_bytes(whole / "image.nii"));
  }

  TEST_CASE("SIGTERM during a write leaves each output whole or absent, no temporary file") {
    riner::test::TempDir dir;
    // A 42 MB ground truth (160 x 256 x 256 floats) takes tens of milliseconds to write.
    riner::test::write_bytes(dir / "g.json", R"({"type": "parallel3d",
        "detector": {"count": [256, 160], "pitch_mm": [1.0, 1.0]},
        "angles": {"count": 8, "range_rad": 3.141592653589793},
        "volume": {"shape": [160, 256, 256], "voxel_mm": 1.0}})");
    int stopped_mid_write = 0;
    for (int attempt = 0; attempt < 8 && stopped_mid_write < 2; ++attempt) {
      const std::filesystem::path out = dir / ("out" + std::to_string(attempt));
      bool writing = false;
      const int status = run_until(
          {"simulate", "--quiet", "--geometry", (dir / "g.json").string(), "--supersample", "1",
           "--out", out.string()},
          [&] { return writing = !riner::test::temporary_files(out).empty(); }, SIGTERM);
      if (!writing) continue;  // it wrote everything before a temporary file was seen
      ++stopped_mid_write;
      CAPTURE(attempt);
      CHECK(WIFSIGNALED(status));
      CHECK(WTERMSIG(status) == SIGTERM);
      CHECK(riner::test::temporary_files(out) == std::vector<std::string>{});
      const std::filesystem::path truth = out / "ground_truth.nii";
      if (std::filesystem::exists(truth)) {
        CHECK(riner::read_array(truth).array.size() == std::size_t{160} * 256 * 256);
      }
    }
    CHECK(stopped_mid_write > 0);
  }

  TEST_CASE("SIGTERM to mpirun: the ranks save their slabs' checkpoints; --resume finishes") {
#ifdef RINER_TEST_MPI
    riner::test::TempDir dir;
    const std::string sim = riner::test::simulate_small_parallel3d(dir);
    const std::vector<std::string> mpirun = {"--allow-run-as-root", "--oversubscribe", "-n", "2",
                                             RINER_CLI_PATH};
    const std::vector<std::string> common = {"reconstruct",   sim + "/sino.npy",
                                             "--geometry",    sim + "/geometry.json",
                                             "--slab-slices", "10",
                                             "--steps",       "4000",
                                             "--quiet"};
    const auto run_mpi = [&](const std::filesystem::path& out, std::vector<std::string> extra,
                             const std::function<bool()>& until, int sig) {
      std::vector<std::string> words = mpirun;
      words.insert(words.end(), common.begin(), common.end());
      words.insert(words.end(), extra.begin(), extra.end());
      words.insert(words.end(), {"--out", out.string()});
      return riner::test::run_program_until("mpirun", words, until, sig);
    };
    const auto never = [] { return false; };
    const std::filesystem::path whole = dir / "whole", stopped = dir / "stopped";
    int status = run_mpi(whole, {}, never, SIGKILL);
    REQUIRE(WIFEXITED(status));
    REQUIRE(WEXITSTATUS(status) == 0);

    const std::filesystem::path checkpoint = stopped / "slabs" / "slab_0000.checkpoint";
    status = run_mpi(
        stopped, {"--checkpoint-minutes", "0.003"},
        [&] { return std::filesystem::exists(checkpoint); }, SIGTERM);
    REQUIRE(std::filesystem::exists(checkpoint));
    CHECK(!(WIFEXITED(status) && WEXITSTATUS(status) == 0));  // mpirun says the job was stopped
    CHECK(!std::filesystem::exists(stopped / "summary.json"));
    CHECK(riner::test::temporary_files(stopped) == std::vector<std::string>{});

    status = run_mpi(stopped, {"--resume"}, never, SIGKILL);
    REQUIRE(WIFEXITED(status));
    REQUIRE(WEXITSTATUS(status) == 0);
    const nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(stopped / "summary.json"));
    REQUIRE(summary["per_slab"].size() == 2);
    const nlohmann::json first = summary["per_slab"][0]["summary"]["resumed_at_step"];
    CAPTURE(first);
    CHECK(first > 0);
    CHECK(first < 4000);
    CHECK(riner::read_array(stopped / "volume").array.data ==
          riner::read_array(whole / "volume").array.data);
    CHECK(riner::test::read_bytes(stopped / "alpha.npy") ==
          riner::test::read_bytes(whole / "alpha.npy"));
    CHECK(!std::filesystem::exists(checkpoint));
#else
    MESSAGE("riner was built without MPI (libopenmpi-dev): nothing to test");
#endif
  }

  TEST_CASE("SIGTERM to one MPI rank alone: every rank saves its checkpoint and stops") {
#ifdef RINER_TEST_MPI
    riner::test::TempDir dir;
    const std::string sim = riner::test::simulate_small_parallel3d(dir);
    // Slabs of 20 000 steps, many seconds each, and no checkpoint but a stop's: rank 0 saves
    // one only if rank 1's stop reaches it (it used to train its slab, and the next, to the end).
    // Two slabs: rank 1 trains one when it is signalled; one slab: rank 1 has none and waits for
    // rank 0 in MPI, where no training report looks for its signal.
    for (const int slabs_in_run : {2, 1}) {
      CAPTURE(slabs_in_run);
      const std::filesystem::path out = dir / ("out" + std::to_string(slabs_in_run));
      const std::filesystem::path slabs = out / "slabs";
      std::vector<std::string> words = {
          "--allow-run-as-root", "--oversubscribe", "-n", "2", RINER_CLI_PATH,
          "reconstruct",         sim + "/sino.npy"};
      words.insert(words.end(), {"--geometry", sim + "/geometry.json", "--slab-slices",
                                 slabs_in_run == 2 ? "10" : "20", "--steps", "20000"});
      // One slab a rank at once, even on a GPU (8 there).
      words.insert(words.end(), {"--checkpoint-minutes", "60", "--workers", "1"});
      words.insert(words.end(), {"--quiet", "--out", out.string()});
      const auto claimed = [&](int slab) {
        const std::string prefix = "slab_000" + std::to_string(slab) + ".";
        std::error_code missing;
        for (const auto& entry : std::filesystem::directory_iterator(slabs, missing)) {
          const std::string name = entry.path().filename().string();
          if (name.rfind(prefix, 0) == 0 && entry.path().extension() == ".claim") return true;
        }
        return false;
      };
      bool signalled = false;
      std::optional<std::chrono::steady_clock::time_point> all_claimed;
      const int status = riner::test::run_program_until(
          "mpirun", words,
          [&] {
            for (int slab = 0; slab < slabs_in_run; ++slab) {
              if (!claimed(slab)) return false;
            }
            // A moment for rank 1 to be training, or (one slab) waiting for rank 0 in MPI.
            if (!all_claimed) all_claimed = std::chrono::steady_clock::now();
            if (std::chrono::steady_clock::now() - *all_claimed < std::chrono::seconds(1)) {
              return false;
            }
            const pid_t rank1 = riner::test::mpi_rank_process(1, out.string());
            signalled = rank1 > 0 && kill(rank1, SIGTERM) == 0;
            return signalled;
          },
          0);  // mpirun itself gets no signal (0 only checks that it runs)
      REQUIRE(signalled);
      CHECK(WIFEXITED(status));
      CHECK(WEXITSTATUS(status) == 128 + SIGTERM);  // mpirun passes on the ranks' exit code
      // No slab trained to its end; each saved where its stop found it.
      for (int slab = 0; slab < slabs_in_run; ++slab) {
        CAPTURE(slab);
        const std::string name = "slab_000" + std::to_string(slab);
        CHECK(!std::filesystem::exists(slabs / (name + ".json")));
        CHECK(std::filesystem::exists(slabs / (name + ".checkpoint")));
      }
      CHECK(riner::test::temporary_files(out) == std::vector<std::string>{});
    }
#else
    MESSAGE("riner was built without MPI (libopenmpi-dev): nothing to test");
#endif
  }

  TEST_CASE("riner's own --processes copies stop on SIGTERM or Ctrl-C; --resume finishes") {
    riner::test::TempDir dir;
    const std::string sim = riner::test::simulate_small_parallel3d(dir);
    const std::vector<std::string> common = {
        "reconstruct", sim + "/sino.npy", "--geometry", sim + "/geometry.json", "--slab-slices",
        "10",          "--steps",         "4000",       "--processes",          "2",
        "--quiet"};
    const auto run = [&](const std::filesystem::path& out, std::vector<std::string> extra,
                         const std::function<bool()>& until, int sig, riner::test::SignalTo to) {
      std::vector<std::string> words = common;
      words.insert(words.end(), extra.begin(), extra.end());
      words.insert(words.end(), {"--out", out.string()});
      return riner::test::run_program_until(RINER_CLI_PATH, words, until, sig, to);
    };
    const auto never = [] { return false; };
    const std::filesystem::path whole = dir / "whole", stopped = dir / "stopped";
    int status = run(whole, {}, never, SIGKILL, riner::test::SignalTo::kProcess);
    REQUIRE(WIFEXITED(status));
    REQUIRE(WEXITSTATUS(status) == 0);

    // The slabs' checkpoints as last written (0 where none).
    const std::filesystem::path slabs = stopped / "slabs";
    const auto saved = [&] {
      std::vector<std::filesystem::file_time_type> times;
      for (const char* name : {"slab_0000.checkpoint", "slab_0001.checkpoint"}) {
        std::error_code none;
        times.push_back(std::filesystem::last_write_time(slabs / name, none));
      }
      return times;
    };
    const auto stop = [&](int sig, riner::test::SignalTo to) {
      const std::vector<std::filesystem::file_time_type> before = saved();
      const int status = run(
          stopped, {"--checkpoint-minutes", "0.003", "--resume"},
          [&] {
            const std::vector<std::filesystem::file_time_type> now = saved();
            return (now[0] != before[0] && now[0] != std::filesystem::file_time_type::min()) ||
                   (now[1] != before[1] && now[1] != std::filesystem::file_time_type::min());
          },
          sig, to);
      CAPTURE(sig);
      REQUIRE(WIFEXITED(status));
      CHECK(WEXITSTATUS(status) == 128 + sig);
      CHECK(!std::filesystem::exists(stopped / "summary.json"));
      CHECK(riner::test::temporary_files(stopped) == std::vector<std::string>{});
    };
    // A scheduler's SIGTERM to the first process alone: it asks its copies to stop (a request),
    // each saves its slab. Then, resumed, Ctrl-C from a terminal: the whole process group. Then
    // SIGTERM to one copy alone: its stop is every copy's (slabs/stop.TOKEN), the run's exit
    // code SIGTERM's (it used to train the other slabs on and end "slab N is not done").
    stop(SIGTERM, riner::test::SignalTo::kProcess);
    stop(SIGINT, riner::test::SignalTo::kGroup);
    stop(SIGTERM, riner::test::SignalTo::kOneChild);

    status = run(stopped, {"--resume"}, never, SIGKILL, riner::test::SignalTo::kProcess);
    REQUIRE(WIFEXITED(status));
    REQUIRE(WEXITSTATUS(status) == 0);
    const nlohmann::json summary =
        nlohmann::json::parse(riner::test::read_bytes(stopped / "summary.json"));
    REQUIRE(summary["per_slab"].size() == 2);
    int resumed = 0;
    for (int slab = 0; slab < 2; ++slab) {
      const nlohmann::json step = summary["per_slab"][slab]["summary"]["resumed_at_step"];
      CAPTURE(slab);
      CAPTURE(step);
      if (step.is_null()) continue;
      ++resumed;
      CHECK(step > 0);
      CHECK(step < 4000);
    }
    CHECK(resumed > 0);
    CHECK(riner::read_array(stopped / "volume").array.data ==
          riner::read_array(whole / "volume").array.data);
    CHECK(riner::test::read_bytes(stopped / "alpha.npy") ==
          riner::test::read_bytes(whole / "alpha.npy"));
  }

  TEST_CASE("--resume (and fbp) removes the temporary files a killed writer on this host left") {
    riner::test::TempDir dir;
    const std::string sim = riner::test::simulate_small_parallel2d(dir, 6);
    const pid_t ended = riner::test::ended_process_id();
    const std::filesystem::path out = dir / "out";
    std::filesystem::create_directories(out);
    const std::filesystem::path dead = out / ("image.nii" + riner::temporary_marker(ended) + "1.0");
    const std::filesystem::path alive =
        out / ("alpha.npy" + riner::temporary_marker(getpid()) + "1.0");
    const std::filesystem::path elsewhere = out / "beta.npy.tmp.0123456789abcdef-1.1.0";
    for (const auto& file : {dead, alive, elsewhere}) riner::test::write_bytes(file, "partial");
    const Run run =
        riner_cli("reconstruct " + sim + "/sino.npy --geometry " + sim +
                      "/geometry.json --steps 300 --quiet --resume --out " + out.string(),
                  dir);
    REQUIRE(run.code == 0);
    CHECK(!std::filesystem::exists(dead));
    CHECK(std::filesystem::exists(alive));      // its writer still runs
    CHECK(std::filesystem::exists(elsewhere));  // another host's: its writer may run
    CHECK(std::filesystem::exists(out / "image.nii"));
    // fbp has no --resume: it removes what a killed earlier write left beside its output.
    const std::filesystem::path fbp_dead =
        dir / ("fbp.npy" + riner::temporary_marker(ended) + "1.0");
    riner::test::write_bytes(fbp_dead, "partial");
    REQUIRE(riner_cli("fbp " + sim + "/sino.npy --quiet --out " + (dir / "fbp.npy").string(), dir)
                .code == 0);
    CHECK(!std::filesystem::exists(fbp_dead));
    CHECK(std::filesystem::exists(dir / "fbp.npy"));
  }
}
