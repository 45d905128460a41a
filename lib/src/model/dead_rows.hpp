// Detector rows that read nothing in any view (a dead row of a flat-panel detector), filled
// for training from the rows beside them, as FBP fills them (analytic/fbp_setup.hpp).
#pragma once

#include <vector>

#include "riner/array.hpp"
#include "riner/geometry.hpp"

namespace riner::model {

// In a 3D scan [views][rows][n_u], each row with no finite reading in any view takes, in each
// view and column, the line between the nearest rows above and below that read there (the
// nearest alone at the detector's ends; NaN stays where neither does). A slice behind such a
// row is seen by no ray (parallel beam), and a field trained without it reads there what it
// never learnt: a cone-beam head slice read 0.0009 against its 0.0100. Returns the rows filled;
// none in 2D or when every row is dead.
std::vector<std::size_t> fill_dead_rows(Array& measurement, const Geometry& g);

}  // namespace riner::model
