// Outputs are atomic and never replace an input.
#include <doctest/doctest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include "riner/error.hpp"
#include "riner/folder_lock.hpp"
#include "riner/io.hpp"
#include "support/fixture.hpp"

TEST_SUITE("output_safety") {
  TEST_CASE("a file this process read cannot be overwritten, by any name") {
    riner::test::TempDir dir;
    const riner::Array a({2, 2}, 1.0f);
    riner::write_array(dir / "in.npy", a);
    riner::read_array(dir / "in.npy");
    const std::string message = (dir / "in.npy").string() + ": refusing to overwrite an input file";
    CHECK_THROWS_WITH_AS(riner::write_array(dir / "in.npy", a), message.c_str(), riner::InputError);
    // Through a different spelling of the same path.
    const auto dotted = dir.path() / "." / "in.npy";
    CHECK_THROWS_AS(riner::write_array(dotted, a), riner::InputError);
    CHECK_THROWS_AS(riner::write_text(dir / "in.npy", "x"), riner::InputError);
    // And through a hard link.
    std::filesystem::create_hard_link(dir / "in.npy", dir / "alias.npy");
    CHECK_THROWS_AS(riner::write_array(dir / "alias.npy", a), riner::InputError);
  }

  TEST_CASE("a write that fails names its target and the system's reason") {
    // Before: "<dir>/<name>.tmp.<hash>: write failed", the temporary's name and no reason.
    riner::test::TempDir dir;
    const std::filesystem::path target = dir / (std::string(250, 'x') + ".npy");
    try {
      riner::write_array(target, riner::Array({2, 2}, 1.0f));
      FAIL("a 254-character name was written");
    } catch (const riner::Error& e) {
      const std::string what = e.what();
      CHECK(what.rfind(target.string() + ": write failed", 0) == 0);
      CHECK(what.find(".tmp.") == std::string::npos);
      CHECK(what.find("File name too long") != std::string::npos);
    }
  }

  TEST_CASE("a read inside an InputScope guards its file during the scope only") {
    riner::test::TempDir dir;
    const riner::Array a({2, 2}, 1.0f);
    riner::write_array(dir / "scoped.npy", a);
    riner::write_array(dir / "held.npy", a);
    riner::read_array(dir / "held.npy");  // the process's own read: held for good
    {
      const riner::InputScope scope;
      riner::read_array(dir / "scoped.npy");
      riner::read_array(dir / "held.npy");
      CHECK_THROWS_AS(riner::write_array(dir / "scoped.npy", a), riner::InputError);
      {
        const riner::InputScope inner;  // a nested call's scope
        riner::read_array(dir / "scoped.npy");
      }
      CHECK_THROWS_AS(riner::write_array(dir / "scoped.npy", a), riner::InputError);
    }
    CHECK_NOTHROW(riner::write_array(dir / "scoped.npy", a));
    CHECK_THROWS_AS(riner::write_array(dir / "held.npy", a), riner::InputError);
    // Another thread's scope, ending while this one's lives, releases only its own reads.
    {
      const riner::InputScope mine;
      riner::read_array(dir / "scoped.npy");
      std::thread([&] {
        const riner::InputScope theirs;
        riner::read_array(dir / "scoped.npy");
      }).join();
      CHECK_THROWS_AS(riner::write_array(dir / "scoped.npy", a), riner::InputError);
    }
    CHECK_NOTHROW(riner::write_array(dir / "scoped.npy", a));
  }

  TEST_CASE("writes leave no temporary files and replace outputs whole") {
    riner::test::TempDir dir;
    riner::write_array(dir / "out.nii", riner::Array({3, 3}, 1.0f));
    riner::write_array(dir / "out.nii", riner::Array({4, 4}, 2.0f));
    CHECK(riner::read_array(dir / "out.nii").array.shape == std::vector<std::size_t>{4, 4});
    int files = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir.path())) {
      (void)entry;
      ++files;
    }
    CHECK(files == 1);
  }

  TEST_CASE("a dead writer's temporary file goes, a zombie's too; a live one's stays") {
    // A SIGKILLed leader's copies linger as zombies until reaped: their files were kept for good.
    riner::test::TempDir dir;
    const pid_t child = ::fork();
    REQUIRE(child >= 0);
    if (child == 0) ::_exit(0);
    // Not reaped: wait until it is a zombie (its /proc state 'Z').
    for (int i = 0; i < 500; ++i) {
      const std::string stat = riner::test::read_bytes("/proc/" + std::to_string(child) + "/stat");
      if (stat.find(") Z") != std::string::npos) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    const std::filesystem::path zombie = dir / ("out.nii" + riner::temporary_marker(child) + "1");
    const std::filesystem::path live =
        dir / ("out.nii" + riner::temporary_marker(::getpid()) + "2");
    riner::test::write_bytes(zombie, "half");
    riner::test::write_bytes(live, "half");
    CHECK(riner::remove_stale_temporaries(dir.path()) == 1);
    CHECK_FALSE(std::filesystem::exists(zombie));
    CHECK(std::filesystem::exists(live));
    ::waitpid(child, nullptr, 0);
  }

  TEST_CASE("one run writes into a folder at a time; its lock goes when it does") {
    riner::test::TempDir dir;
    std::string holder;
    {
      const riner::FolderLock first(dir.path());
      REQUIRE(first.held());
      holder = riner::test::read_bytes(riner::FolderLock::file_in(dir.path()));
      // Appended, not ":" + a string: GCC 12 takes that insert for an overlapping copy
      // (-Wrestrict, a false positive).
      std::string pid_tag = ":";
      pid_tag += std::to_string(::getpid());
      CHECK(holder.find(pid_tag) != std::string::npos);
      holder.pop_back();  // its newline
      // A second lock conflicts even within this process (an open file's lock, not a process's).
      const std::string message = dir.path().string() + ": another riner run (" + holder +
                                  ") is writing into this folder: wait for it to end, or choose "
                                  "another output folder";
      CHECK_THROWS_WITH_AS(riner::FolderLock(dir.path()), message.c_str(), riner::InputError);
      // Reading the lock's file elsewhere in the process does not drop it.
      (void)riner::test::read_bytes(riner::FolderLock::file_in(dir.path()));
      CHECK_THROWS_AS(riner::FolderLock(dir.path()), riner::InputError);
    }
    const riner::FolderLock after(dir.path());
    CHECK(after.held());
  }

  TEST_CASE("a missing output directory is a clear error") {
    riner::test::TempDir dir;
    const auto path = dir / "no_such_dir" / "x.npy";
    CHECK_THROWS_WITH_AS(
        riner::write_array(path, riner::Array({1}, 0.0f)),
        (path.string() + ": output directory " + (dir / "no_such_dir").string() + " does not exist")
            .c_str(),
        riner::InputError);
  }

  TEST_CASE("PNG previews window by percentiles and refuse non-images") {
    riner::test::TempDir dir;
    riner::Array ramp({10, 100});
    for (std::size_t i = 0; i < ramp.size(); ++i) ramp.data[i] = static_cast<float>(i % 100);
    const riner::Window w = riner::percentile_window(ramp);
    CHECK(w.lo == doctest::Approx(1.0));
    CHECK(w.hi == doctest::Approx(98.0));
    riner::write_png(dir / "ramp.png", ramp);
    const std::string png = riner::test::read_bytes(dir / "ramp.png");
    CHECK(png.substr(1, 3) == "PNG");
    CHECK_THROWS_AS(riner::write_png(dir / "bad.png", riner::Array({5})), riner::InputError);
  }
}

TEST_SUITE("previews") {
  TEST_CASE("a volume previews as its three central slices, +z up") {
    // value = 100 z + 10 y + x on a [5, 3, 4] volume
    riner::Array v({5, 3, 4});
    for (std::size_t z = 0; z < 5; ++z)
      for (std::size_t y = 0; y < 3; ++y)
        for (std::size_t x = 0; x < 4; ++x)
          v.data[(z * 3 + y) * 4 + x] = 100.0f * z + 10.0f * y + x;
    const riner::Array p = riner::preview_image(v);
    REQUIRE(p.shape == std::vector<std::size_t>{5, 4 + 4 + 4 + 4 + 3});
    CHECK(p(1, 2) == 212.0f);       // axial: slice 2, row 1, column 2
    CHECK(p(3, 0) == 0.0f);         // below the 3-row axial slice: padding
    CHECK(p(0, 8 + 3) == 413.0f);   // coronal: top row is z = 4, row y = 1
    CHECK(p(4, 8 + 0) == 10.0f);    // bottom row z = 0
    CHECK(p(0, 16 + 2) == 422.0f);  // sagittal: z = 4, y = 2, column x = 2
    CHECK(riner::preview_image(riner::Array({3, 2})).shape == std::vector<std::size_t>{3, 2});
    CHECK_THROWS_AS(riner::preview_image(riner::Array({2, 2, 2, 2})), riner::InputError);
  }
}
