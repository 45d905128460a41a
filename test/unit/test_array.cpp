#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "riner/array.hpp"
#include "riner/error.hpp"

TEST_SUITE("array") {
  TEST_CASE("shape_size multiplies and refuses overflow") {
    CHECK(riner::shape_size({3, 4, 5}) == 60);
    CHECK(riner::shape_size({0, 7}) == 0);
    const std::size_t big = std::numeric_limits<std::size_t>::max() / 2;
    CHECK_THROWS_AS(riner::shape_size({big, 3}), riner::InputError);
    CHECK(riner::shape_string({360, 500}) == "[360, 500]");
  }

  TEST_CASE("constructor checks that data matches the shape") {
    CHECK_THROWS_AS(riner::Array({2, 3}, std::vector<float>(5)), riner::InputError);
    riner::Array a({2, 3}, std::vector<float>{0, 1, 2, 3, 4, 5});
    CHECK(a(1, 2) == 5.0f);
    riner::Array b({2, 2, 2}, 1.5f);
    CHECK(b(1, 1, 1) == 1.5f);
  }

  TEST_CASE("stats separate NaN and infinities from the finite values") {
    const float inf = std::numeric_limits<float>::infinity();
    riner::Array a({6}, std::vector<float>{1.0f, 3.0f, NAN, inf, -inf, 2.0f});
    const riner::ArrayStats s = riner::compute_stats(a);
    CHECK(s.finite == 3);
    CHECK(s.nan == 1);
    CHECK(s.pos_inf == 1);
    CHECK(s.neg_inf == 1);
    CHECK(s.non_finite() == 3);
    CHECK(s.min == 1.0);
    CHECK(s.max == 3.0);
    CHECK(s.mean == doctest::Approx(2.0));
    CHECK(s.stddev == doctest::Approx(std::sqrt(2.0 / 3.0)));
  }
}
