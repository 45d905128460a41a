// Training checkpoints (Reconstructor::save_checkpoint, resume_from): a run stopped, saved and
// resumed in another Reconstructor gives the uninterrupted run's bits on both engines; a
// checkpoint of another run or a damaged file is refused with a clear error.
#include <doctest/doctest.h>

#include <cstdint>
#include <cstring>
#include <string>

#include "riner/error.hpp"
#include "riner/reconstructor.hpp"
#include "support/fixture.hpp"
#include "support/tiny_problem.hpp"

namespace {

// The tiny scan's settings with a tail average over the last 30 of 60 steps, so a checkpoint
// taken inside the tail holds a sum that the result needs.
riner::RinerConfig checkpoint_config(riner::Engine engine) {
  riner::RinerConfig c = riner::test::tiny_config();
  c.engine = engine;
  c.training.steps = 60;
  c.training.tail_average_steps = 30;
  return c;
}

std::string error_of(riner::Reconstructor& r, const std::filesystem::path& path) {
  try {
    r.resume_from(path);
  } catch (const riner::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_SUITE("checkpoint") {
  TEST_CASE("a run resumed from a checkpoint is the uninterrupted run, bit for bit") {
    const riner::test::TinyProblem t = riner::test::tiny_problem(5);
    for (riner::Engine engine : {riner::Engine::kOpenCL, riner::Engine::kReference}) {
      CAPTURE(riner::engine_name(engine));
      const riner::RinerConfig c = checkpoint_config(engine);
      riner::Reconstructor whole(t.scan, c, riner::test::device());
      whole.run();
      const riner::test::TempDir dir;
      for (int stop : {10, 45}) {  // before the tail average's first snapshot, and inside it
        CAPTURE(stop);
        {
          riner::Reconstructor first(t.scan, c, riner::test::device());
          first.step(stop);
          first.save_checkpoint(dir / "training.checkpoint");
        }
        riner::Reconstructor resumed(t.scan, c, riner::test::device());
        resumed.resume_from(dir / "training.checkpoint");
        CHECK(resumed.steps_done() == stop);
        resumed.run();
        CHECK(resumed.steps_done() == whole.steps_done());
        CHECK(resumed.field_image().data == whole.field_image().data);
        CHECK(resumed.image().data == whole.image().data);
        CHECK(resumed.alpha().data == whole.alpha().data);
        CHECK(resumed.beta().data == whole.beta().data);
        const auto h_resumed = resumed.history();
        const auto h_whole = whole.history();
        REQUIRE(h_resumed.size() == h_whole.size());
        for (std::size_t i = 0; i < h_whole.size(); ++i) {
          CHECK(h_resumed[i].data_loss == h_whole[i].data_loss);
        }
        CHECK(resumed.stats().samples == whole.stats().samples);
        CHECK(resumed.stats().tail_average_snapshots == whole.stats().tail_average_snapshots);
      }
    }
  }

  TEST_CASE("a checkpoint of another run, or a damaged one, is refused") {
    const riner::test::TinyProblem t = riner::test::tiny_problem(5);
    const riner::RinerConfig c = checkpoint_config(riner::Engine::kOpenCL);
    const riner::test::TempDir dir;
    const std::filesystem::path saved = dir / "training.checkpoint";
    {
      riner::Reconstructor r(t.scan, c, riner::test::device());
      r.step(5);
      r.save_checkpoint(saved);
    }
    riner::Reconstructor other_scan(riner::test::tiny_problem(6).scan, c, riner::test::device());
    CHECK(error_of(other_scan, saved).find("another scan") != std::string::npos);
    riner::RinerConfig other = c;
    other.training.steps = 80;
    riner::Reconstructor other_settings(t.scan, other, riner::test::device());
    CHECK(error_of(other_settings, saved).find("other settings") != std::string::npos);
    riner::RinerConfig reference = c;
    reference.engine = riner::Engine::kReference;
    riner::Reconstructor other_engine(t.scan, reference);
    // The engine is a setting too.
    CHECK(!error_of(other_engine, saved).empty());

    riner::Reconstructor r(t.scan, c, riner::test::device());
    const std::string bytes = riner::test::read_bytes(saved);
    riner::test::write_bytes(dir / "half", bytes.substr(0, bytes.size() / 2));
    CHECK(error_of(r, dir / "half").find("truncated or corrupt") != std::string::npos);
    riner::test::write_bytes(dir / "longer", bytes + "x");
    CHECK(error_of(r, dir / "longer").find("truncated or corrupt") != std::string::npos);
    // Bytes flipped inside (a disk's or a copy's damage, which no kill can do): the checksum.
    std::string flipped = bytes;
    flipped[flipped.size() / 2] = static_cast<char>(~flipped[flipped.size() / 2]);
    riner::test::write_bytes(dir / "flipped", flipped);
    CHECK(error_of(r, dir / "flipped").find("checksum does not match") != std::string::npos);
    riner::test::write_bytes(dir / "text", "not a checkpoint at all");
    CHECK(error_of(r, dir / "text").find("not a riner training checkpoint") != std::string::npos);
    riner::test::write_bytes(dir / "empty", "");
    CHECK(error_of(r, dir / "empty").find("not a riner training checkpoint") != std::string::npos);
    CHECK(error_of(r, dir / "missing").find("cannot read") != std::string::npos);
    // A refused checkpoint leaves the run where it was.
    CHECK(r.steps_done() == 0);
    r.resume_from(saved);
    CHECK(r.steps_done() == 5);
  }

  TEST_CASE("a checkpoint of format 1 (no checksum) still resumes") {
    const riner::test::TinyProblem t = riner::test::tiny_problem(5);
    const riner::RinerConfig c = checkpoint_config(riner::Engine::kOpenCL);
    const riner::test::TempDir dir;
    {
      riner::Reconstructor r(t.scan, c, riner::test::device());
      r.step(5);
      r.save_checkpoint(dir / "v2");
    }
    // Format 1 is format 2 without the trailing 8-byte checksum, the version after the magic.
    std::string bytes = riner::test::read_bytes(dir / "v2");
    bytes.resize(bytes.size() - 8);
    const std::uint32_t one = 1;
    std::memcpy(bytes.data() + 8, &one, sizeof(one));
    riner::test::write_bytes(dir / "v1", bytes);
    riner::Reconstructor r(t.scan, c, riner::test::device());
    r.resume_from(dir / "v1");
    CHECK(r.steps_done() == 5);
    const std::uint32_t three = 3;
    std::memcpy(bytes.data() + 8, &three, sizeof(three));
    riner::test::write_bytes(dir / "v3", bytes);
    riner::Reconstructor other(t.scan, c, riner::test::device());
    CHECK(error_of(other, dir / "v3").find("format 3") != std::string::npos);
  }
}
