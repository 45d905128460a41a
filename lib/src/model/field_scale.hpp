// The field's own scale. Adam moves the field's output by steps of about one size whatever the
// scan, so the image's noise and its smallest detail sit at a fixed level of the field's value:
// a scan whose attenuation per mm lies far from the scans the defaults were chosen on trained
// to speckle (readings x 0.001: 16.4 dB against 30.8) or lost its fine rings (a synchrotron's
// micrometre pixels given in mm, mu x 1000: 24.1 dB, ten live elements taken for dead). The field
// learns y = mu * field_per_mu instead, a power of two (exact in floating point) that brings
// such a scan's typical mu into the range those scans span; 1 inside it, so they train as
// before to the bit.
#pragma once

#include "riner/array.hpp"
#include "riner/geometry.hpp"

namespace riner::model {

// The typical attenuation per mm: the median over views of each view's largest reading, over the
// grid's width in mm. The scans the defaults were chosen on read 0.0015 (a neutron wood slice)
// to 0.03 (an HTC2022 disc; DeepLesion slices 0.014-0.017, the default simulation 0.024).
double typical_mu(const Array& measurement, const Geometry& g);
constexpr double kLeastTypicalMu = 1.0 / 1024.0;
constexpr double kMostTypicalMu = 1.0 / 16.0;
// For a typical_mu outside [kLeastTypicalMu, kMostTypicalMu]: the power of two that puts
// typical_mu * it nearest kTargetTypicalMu; 1 inside, or when the scan reads nothing (0).
constexpr double kTargetTypicalMu = 1.0 / 64.0;
double field_per_mu(double typical_mu);

// The geometry with every length divided by `factor` (pitches, distances, voxel, grid height):
// the same rays and grid in another unit, so that a ray's sum of y * dx is its reading.
Geometry lengths_divided(Geometry g, double factor);

}  // namespace riner::model
