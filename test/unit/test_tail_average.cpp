// Which steps' parameters tail averaging takes (model/tail_average.hpp): every tenth step counted
// back from the last planned one, inside the tail only.
#include <doctest/doctest.h>

#include <vector>

#include "model/tail_average.hpp"

TEST_SUITE("tail average") {
  TEST_CASE("snapshots every 10 steps back from the last, inside the tail") {
    const riner::model::TailAverage tail{25, 100};
    std::vector<int> taken;
    for (int s = 0; s < 120; ++s) {
      if (tail.takes(s)) taken.push_back(s);
    }
    CHECK(taken == std::vector<int>{79, 89, 99});
    CHECK(tail.snapshots(0) == 0);
    CHECK(tail.snapshots(79) == 0);
    CHECK(tail.snapshots(80) == 1);
    CHECK(tail.snapshots(100) == 3);
    CHECK(tail.snapshots(101) == 0);  // past the plan: the last step's parameters
  }

  TEST_CASE("no tail takes nothing; a tail of the whole run starts at its first snapshot") {
    const riner::model::TailAverage none{0, 100};
    for (int s = 0; s < 100; ++s) CHECK_FALSE(none.takes(s));
    CHECK(none.snapshots(100) == 0);
    const riner::model::TailAverage whole{100, 100};
    CHECK(whole.takes(9));
    CHECK_FALSE(whole.takes(0));
    CHECK(whole.snapshots(100) == 10);
    const riner::model::TailAverage one{1, 7};
    CHECK(one.takes(6));
    CHECK(one.snapshots(7) == 1);
  }
}
