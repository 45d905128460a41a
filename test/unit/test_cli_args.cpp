#include <doctest/doctest.h>

#include <vector>

#include "cli_args.hpp"

namespace {

struct Argv {
  std::vector<std::string> storage;
  std::vector<char*> pointers;
  explicit Argv(std::vector<std::string> args) : storage(std::move(args)) {
    for (std::string& s : storage) pointers.push_back(s.data());
  }
  int argc() { return static_cast<int>(pointers.size()); }
  char** argv() { return pointers.data(); }
};

riner::app::Args make_args() {
  riner::app::Args args("demo", "test command");
  args.positional("FILE", "input").option("steps", "N", "steps", "100").flag("fast", "go fast");
  args.output_flags();
  return args;
}

}  // namespace

TEST_SUITE("cli_args") {
  TEST_CASE("positional, options in both spellings, flags and defaults") {
    Argv argv({"riner", "demo", "scan.npy", "--steps=250", "--fast", "--json"});
    auto args = make_args();
    REQUIRE(args.parse(argv.argc(), argv.argv(), 2));
    CHECK(args.get("FILE") == "scan.npy");
    CHECK(args.integer("steps") == 250);
    CHECK(args.is_set("fast"));
    CHECK(args.is_set("json"));
    CHECK_FALSE(args.is_set("quiet"));

    Argv argv2({"riner", "demo", "--steps", "7", "x.nii"});
    auto args2 = make_args();
    REQUIRE(args2.parse(argv2.argc(), argv2.argv(), 2));
    CHECK(args2.integer("steps") == 7);
    Argv argv3({"riner", "demo", "x.nii"});
    auto args3 = make_args();
    REQUIRE(args3.parse(argv3.argc(), argv3.argv(), 2));
    CHECK(args3.integer("steps") == 100);
  }

  TEST_CASE("a list option given more than once joins its lists; another option's last wins") {
    Argv argv({"riner", "demo", "x.nii", "--set", "a=1,b=2", "--steps", "5", "--set=c=3",
               "--set", "", "--steps", "6", "--set", "d=4"});
    auto args = make_args();
    args.list_option("set", "NAME=VALUE,...", "settings");
    REQUIRE(args.parse(argv.argc(), argv.argv(), 2));
    CHECK(args.get("set") == "a=1,b=2,c=3,d=4");
    CHECK(args.integer("steps") == 6);
    Argv none({"riner", "demo", "x.nii"});
    auto defaults = make_args();
    defaults.list_option("set", "NAME=VALUE,...", "settings");
    REQUIRE(defaults.parse(none.argc(), none.argv(), 2));
    CHECK(defaults.get("set").empty());
    Argv empty_first({"riner", "demo", "x.nii", "--set", "", "--set", "a=1"});
    auto joined = make_args();
    joined.list_option("set", "NAME=VALUE,...", "settings");
    REQUIRE(joined.parse(empty_first.argc(), empty_first.argv(), 2));
    CHECK(joined.get("set") == "a=1");
  }

  TEST_CASE("bad usage is a UsageError with a precise message") {
    using riner::app::UsageError;
    auto expect = [](std::vector<std::string> words, const std::string& message) {
      Argv argv(std::move(words));
      auto args = make_args();
      try {
        args.parse(argv.argc(), argv.argv(), 2);
        FAIL("no error for " << message);
      } catch (const UsageError& e) {
        CHECK(std::string(e.what()) == message);
      }
    };
    expect({"riner", "demo"}, "missing FILE");
    expect({"riner", "demo", "a", "b"}, "unexpected argument 'b'");
    expect({"riner", "demo", "a", "--nope"}, "unknown option --nope");
    expect({"riner", "demo", "a", "--steps"}, "--steps needs a value (N)");
    expect({"riner", "demo", "a", "--fast=1"}, "--fast takes no value");

    Argv argv({"riner", "demo", "a", "--steps", "ten"});
    auto args = make_args();
    REQUIRE(args.parse(argv.argc(), argv.argv(), 2));
    CHECK_THROWS_WITH_AS(args.integer("steps"), "--steps expects an integer, got 'ten'",
                         UsageError);
  }
}
