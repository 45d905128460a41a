// Shared main of every test tier: prints the seed, captures library warnings so a test can
// assert on them (and they do not clutter the log).
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <cstdio>

#include "riner/log.hpp"
#include "support/fixture.hpp"

namespace riner::test {
void record_warning(std::string_view message);
}

int main(int argc, char** argv) {
  std::printf("[riner tests] seed %llu (override with RINER_TEST_SEED)\n",
              static_cast<unsigned long long>(riner::test::seed()));
  riner::set_warning_handler(riner::test::record_warning);
  doctest::Context context;
  context.applyCommandLine(argc, argv);
  return context.run();
}
