// Lines that read nothing, filled from the lines beside them: FBP's repair of dead detector rows
// and lost views (analytic/fbp_setup.hpp), and training's of rows dead in every view
// (model/dead_rows.hpp).
#pragma once

#include <cstddef>
#include <vector>

namespace riner::util {

// Fills each flagged line of `empty` (its size lines of `size` values, `stride` apart from
// `base`) from the nearest unflagged lines on either side: linearly between two, a copy beside
// one. A value takes the finite side where the other is NaN, and stays where neither is finite.
// The filled lines are unflagged; false when no line was unflagged (nothing filled).
bool fill_between(float* base, std::size_t stride, std::size_t size, std::vector<bool>& empty);

}  // namespace riner::util
