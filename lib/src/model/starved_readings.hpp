// Readings of +inf (no light reached the element: -ln 0) mean one of two things. Where the object
// stopped the beam (metal, photon starvation) the ray's line integral is at least about the
// largest finite reading of nine views in ten (one bad reading does not set it): a bound
// training keeps (a censored reading; kernels/ray_sum.cl, ray_loss). Where an element read
// nothing while the rays beside it saw light, it is dead or dying: unread, as NaN is, which
// beta switches off.
//
// Along each detector line, a run of +inf is a stopped beam when it is wider than
// kWidestDeadRun elements (a 9-pixel metal disc: runs of 7-9; a dead element: 1), or when a
// reading beside it (the nearest finite one on either side) reaches kStarvedNeighbourShare of the
// largest (the few photons at a dense edge) and its element is not dark for a run of
// response_change_min_views views or more there (an element dying part-way in the middle of a
// body, whose rays read near the largest; the dead columns of the shared neutron scan sit among
// rays at 0.36 of it), or when it is part of a trace that moves across the detector with the
// views and follows one point's projection (a thin wire's, its partly covered neighbours far
// below the largest; a dead element that drifts follows none). But kWidestDeadRun + 1 or more
// elements of a run dark together from one view to the scan's end (or from its start to one view),
// for that many views, are a module failing, and a run filling a whole line (a blank frame) says
// nothing: both unread. An element that reads nothing in any view is dead whatever its neighbours
// read (a rule that took a block whose neighbours were dark in half the views for metal made an
// audit's dead modules beside a metal's trace, or beside a dying element, into bright bounds),
// except in a run wider than kWidestDeadRun, dark in every view it reads, centred on the rotation
// axis (within a pixel), whose elements on both sides, in three quarters of the views with light,
// are dark or read kStarvedNeighbourShare of the largest and a step above the readings beyond
// them: metal on the axis stops those rays in every view (a 3/mm pin there read 0.62 for 3.0
// as dead elements), where a dead element or module off the axis leaves its conjugate rays
// across the axis lit, and one on the axis of a thick body has rays beside it that read as
// much as those beyond.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>

#include "riner/array.hpp"
#include "riner/geometry.hpp"

namespace riner::model {

constexpr std::size_t kWidestDeadRun = 2;
constexpr double kStarvedNeighbourShare = 0.75;
// The bounds' floor: this quantile over the views of each view's largest finite reading.
constexpr double kFloorViewQuantile = 0.9;

struct StarvedReadings {
  std::size_t count = 0;  // +inf readings kept as bounds
  float floor =
      0.0f;  // the bound: the views' largest finite readings' kFloorViewQuantile (0: none)
};

// `measurement` is [views, elements] or [views, rows, columns]. Sets the +inf readings that are
// no bound to NaN. Finite readings beyond riner::largest_reading are left out of the largest.
// `axis_column`: the column the rotation axis projects onto (NaN: unknown, no run is read as
// stopped on the axis).
// `geometry`: the scan's (its views' projections), for traces that move across the detector
// with the views; none: no run is read as one.
StarvedReadings mark_starved_readings(Array& measurement, std::size_t views,
                                      double axis_column = std::numeric_limits<double>::quiet_NaN(),
                                      const Geometry* geometry = nullptr);
// The detector column the rotation axis projects onto (riner/rays.hpp).
double axis_column(const Geometry& g);
// The same for a scan's readings under `g`: corrupt spikes first set NaN (as training reads
// them, riner/scan.hpp's mark_corrupt_readings), then the bounds about axis_column(g).
StarvedReadings mark_starved_readings(Array& measurement, const Geometry& g);

// The first finite reading of a detector line of n from `from` on, stepping by `step` (-1:
// leftwards); NaN where none.
float nearest_finite(const float* line, long from, long step, long n);

// A kept bound: +inf after mark_starved_readings.
inline bool is_starved(float reading) { return reading == std::numeric_limits<float>::infinity(); }
// An unread reading (NaN, -inf): not finite, and no bound.
inline bool is_unread(double reading) { return !std::isfinite(reading) && !(reading > 0.0); }

}  // namespace riner::model
