// The rotation axis of a full-turn fan-beam scan from conjugate rays: a ray leaves the source
// circle where the source of a view about half a turn later sits, and that view's ray back
// through the same line reads the same line integral. Both rays are computed with the
// geometry's detector offset, so they meet only when that offset is the scan's: the offset is
// where the mean squared difference of every ray and its conjugate (read between the two
// nearest views, each through the line's point nearest the axis) is least: every 2 px on a
// sixth of the rays, half pixels around the best on all, then a parabola through the three
// best. The geometry's own conventions (rotation direction, detector orientation) come in
// through its ray functions, so nothing here assumes them.
#pragma once

#include <cstddef>
#include <limits>
#include <optional>

#include "riner/scan.hpp"

namespace riner::preprocessing {

struct ConjugateAxis {
  double offset_px = 0.0;  // the detector offset (geometry's u) that puts the axis there
  std::size_t rays = 0;    // ray pairs compared at the best offset of the half-pixel grid
  bool half_acquisition = false;  // found beyond the detector's central half
  // The best at an end of the search around the geometry's offset (not beyond the central
  // half): no answer, the axis lies farther (offset_px that end).
  bool at_search_end = false;
};

// Fan beam (2D). Searches the geometry's offset +- search_px, and on from an end of it where the
// best lies there, up to the detector's central half (kCentreSearchShare of its width either
// way; a search of 32 px on 240 elements said 34.50 for an axis 40 px off, its end taken for an
// answer; at_search_end when it ends there); the whole central half where the geometry's
// offset lies farther than search_px from 0, and also where it declares a half acquisition
// (taken over the search about that offset and its mirror image where it matches 4 times
// better, relatively); where the geometry puts the axis
// in the detector's central half, also the offsets beyond it (a half acquisition: the axis near
// one end, only the rays around it have conjugates on the detector), by the mismatch relative
// to the spread of the readings compared, taken where that is under a quarter of the best
// around the geometry's offset. nullopt when the views do not cover a full turn less two steps,
// evenly spaced (within 10% of the step), or the detector is under 8 elements.
// The search around the geometry's offset reads `scan`: the object's mean per element, which
// a full turn's stripes share, gives its cost a basin about the axis (without it, an axis 40 px
// off was taken for one 58 px the other way). The half-pixel search, and the one beyond the
// central half, read `fine_scan`: the readings less each element's mean over the turn
// (centre.cpp), in which a ring's stripes (an element and its conjugate offset alike at no
// candidate) no longer pull the best (1.7 px on a ringed fan scan of a faint object).
std::optional<ConjugateAxis> conjugate_axis(const Scan& scan, const Scan& fine_scan,
                                            double search_px = 32.0);

// How far the fan's source sits from its detector, read from conjugate rays: a ray meets its
// conjugate only with the fan angles (element position over the source-detector distance) the
// scan had, so a distance given wrong (a TIGRE user's source-detector distance given as the
// origin-detector distance; a detector pitch before binning) pairs rays with the wrong views
// at every offset. `scale`: the factor on the geometry's source-detector distance (as a factor
// 1 / scale on the pitch: the fan angles alone count, not where along the ray the source is)
// whose best offset (within 2 px of offset_px) matches best; the relative costs there and at
// the geometry's own distance. Fan beam over a full turn only; nullopt otherwise.
struct FanDistanceFit {
  double scale = 1.0;
  double offset_px = 0.0;
  double cost = 0.0;           // relative, at scale and its best offset
  double cost_as_given = 0.0;  // relative, at scale 1 and its best offset
};
std::optional<FanDistanceFit> conjugate_fan_distance(const Scan& fine_scan, double offset_px);

// Which way the fan turned: views that turned the other way (or a detector whose columns run the
// other way) pair every ray with the wrong conjugate. The relative costs as given and with the
// angles negated, each at its best offset within 2 px of offset_px or of -offset_px (the
// columns reversed mirror the offset; a sign slip alone is not a reversed sense). Fan beam over
// a full turn only; nullopt otherwise.
struct FanSense {
  double cost_as_given = std::numeric_limits<double>::infinity();
  double cost_reversed = std::numeric_limits<double>::infinity();
};
std::optional<FanSense> conjugate_sense(const Scan& fine_scan, double offset_px);

}  // namespace riner::preprocessing
