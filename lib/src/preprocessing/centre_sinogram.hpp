// The rotation axis from the whole sinogram (Vo, Drakopoulos, Atwood, Reinhard 2014, "Reliable
// method for calculating the center of rotation in parallel-beam tomography", Opt. Express
// 22(16), 19078; algotom's find_center_vo): the views of one half-turn
// followed by their mirror images about the axis are the sinogram of a full turn, in which every
// point of the object traces one unbroken sinusoid, and the 2D spectrum of such a sinogram stays
// inside a double wedge (harmonic m of a point at radius r: |m| <= r times the detector
// frequency). A wrong axis breaks every sinusoid at the two seams and spreads energy outside
// the wedge. The axis is where the mean spectral magnitude outside it is least: a search over
// the central half of the detector on a binned sinogram, then a finer one at full width, then a
// parabola through the three best. Every view counts (one noisy or dim view moves it little:
// a view's level shift lies on the spectrum's zero detector frequency, left out), and a scan
// of 179.5 degrees, which has no view pair, works as well.
#pragma once

#include <cstddef>
#include <optional>

#include "riner/scan.hpp"

namespace riner::preprocessing {

struct SinogramAxis {
  double axis_column = 0.0;  // 0-based, fractional
  std::size_t views = 0;     // of the half-turn used
  std::size_t rows = 0;      // detector rows searched (their median)
};

// Parallel beam only. nullopt when the views do not cover a half-turn less 4 steps from the
// first, or are not evenly spaced within it (within 10% of the step). No rows (axis_column NaN)
// when no row's measure has a minimum inside the search: its best at either end of it.
std::optional<SinogramAxis> sinogram_axis(const Scan& scan);

}  // namespace riner::preprocessing
