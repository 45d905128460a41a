// Detector elements stuck at one reading, found from the measurement before training. A dead
// or hot pixel, row or column of a real detector often reads a steady value (the flat, the
// dark, saturation) instead of non-finite ones; the data term cannot tell it from an object
// until beta learns it, and on a 3D detector each pixel's beta sees too few rays for that
// (docs/history/RESULTS.md, issue 14: rows stuck at 0 and 2.5 kept beta ~0.6 after 12 000 steps).
//
// An element is stuck when its readings vary over the views by less than 5% of the variance
// of both its neighbours on one line through it (left and right, or above and below in 3D; at
// distance 1 or 2, so bands up to three wide are seen), and those neighbours vary well above
// the noise (10 sigma). One-sided silhouettes (air beside the object's edge) have only one
// varying neighbour; an element on the axis of a centred object has steady neighbours too.
// Wider bands along a detector row (a dead module), up to a quarter of its width, are stuck
// where every column in them is steady against the varying columns that bound the band on both
// sides (a column steady over a full turn lies beyond all off-centre matter, out to the
// detector's end).
#pragma once

#include <cstdint>
#include <vector>

#include "riner/scan.hpp"

namespace riner::model {

// Per element (row-major [rows, columns]; one row in 2D): 1 where stuck. Elements with a
// non-finite reading are left to that (they are dead already).
std::vector<std::uint8_t> stuck_elements(const Scan& scan, double noise_sigma);

}  // namespace riner::model
