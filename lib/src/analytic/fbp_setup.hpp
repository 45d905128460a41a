// The host-side parts of FBP/FDK shared by both engines: repairing non-finite measurements,
// cosine pre-weighting for divergent beams, the ramp-filter taps and the per-view weights.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "riner/array.hpp"
#include "riner/fbp.hpp"
#include "riner/geometry.hpp"
#include "riner/scan.hpp"

namespace riner::analytic {

// Replaces NaN/inf, and readings beyond kLargestReading (riner/scan.hpp), in every detector row of
// every view by linear interpolation between the nearest valid neighbours (constant beyond the last
// one). A row with none takes the nearest rows of its view that have some (of `rows` per view), a
// view with none the nearest views; 0 only where nothing is valid. Returns the number replaced.
std::size_t repair_non_finite(Array& measurement, std::size_t n_u, std::size_t rows = 1);

// Multiplies fan/cone measurements by SDD / sqrt(SDD^2 + u^2 + v^2) (the cosine of the ray's
// angle to the central ray); parallel beams are unchanged.
void cosine_weight(Array& measurement, const Geometry& g);

// A full turn seen by a detector whose one side reaches much farther from the axis than the
// other (half acquisition, an offset axis): a ray beyond the near side's reach has no conjugate,
// so it counts twice, and across the overlap |d| < o around the axis the two conjugates blend as
// 2 w(d) with w(d) + w(-d) = 1 (sin^2 in the ray's distance d from the axis), which also takes
// the near edge to 0. The filtered views reach beyond the near edge (the ramp's tails), where the
// conjugates need them, so the detector is extended there with zeros to mirror the far side:
// `measurement` is weighted and widened, `g` gets the new element count and offset (the old
// elements stay where they were). Returns o in mm; 0 (nothing changed) for a centred detector
// (near side over 80% of the far one's reach), a scan short of a full turn, or a detector on one
// side of the axis only.
double extend_half_acquisition(Array& measurement, Geometry& g);

// Detector spacing the filter works in: the pitch, scaled to the isocentre for divergent beams.
double filter_spacing(const Geometry& g);

// Convolution taps h[k], k = -(n_u - 1) .. n_u - 1 stored at k + n_u - 1: the band-limited ramp
// (Ram-Lak, Kak & Slaney eq. 3.61) times the window, designed on a zero-padded grid of
// 2^ceil(log2(2 n_u)) so that linear convolution with them equals FFT filtering with padding.
// Already multiplied by the spacing tau: filtered = sum_k taps[k] * p[j - k].
std::vector<double> filter_taps(std::size_t n_u, double tau, FbpFilter filter);

// Per-view backprojection weights: each view's share of the angular coverage (angles taken
// modulo pi for parallel beams, 2 pi for divergent ones), times 1/2 for divergent beams, so
// that sum(weights) = pi either way. Sets *short_scan when part of the period was never seen.
std::vector<double> view_weights(const Geometry& g, bool* short_scan);

// A fan or cone beam's short scan that Parker's weights complete: evenly stepping views over
// less than a turn but at least half a turn plus the fan. Its step, each column's fan angle
// and Parker's half fan; nullopt for any other scan.
struct ParkerSpan {
  double step = 0.0;
  std::vector<double> gamma;
  double delta = 0.0;
};
std::optional<ParkerSpan> parker_span(const Geometry& g);
// Whether the views leave lines of the field never measured (part of the period unseen, and no
// Parker-completed short scan): FBP streaks there and riner's field is unconstrained.
bool views_miss_lines(const Geometry& g);

// Parker's weights (Parker 1982, with the overscan of a range beyond half a turn plus the fan)
// for a fan or cone beam whose views step evenly over less than a full turn but at least half
// a turn plus the fan: every line is measured once or twice, and each pair of conjugate rays
// (beta, gamma) and (beta + pi + 2 gamma, -gamma) gets weights that sum to 1, falling smoothly
// to 0 at the ends of the range. Multiplies the readings and makes `view_weights` each view's
// step, counted once (a full turn's halves count each line twice). False, and nothing changed,
// for a parallel beam, a full turn, uneven views or too short a range.
bool parker_weight(Array& measurement, const Geometry& g, std::vector<double>& view_weights);

}  // namespace riner::analytic
