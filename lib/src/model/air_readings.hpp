// Which readings say that their ray crossed only air: the evidence the air carving
// (model/occupancy.hpp) stands on, read off the measurement alone.
//
// - The elements that read air in every view (steady, near 0: the scan's edges) give the
//   scan's noise, each view's level (a source that flickers moves every reading of a view
//   alike) and noise, and the band of plausible offsets (-ln alpha). Steady means: a spread
//   close to the quietest elements', and a range without the two highest and two lowest readings
//   within 12 sigma (one or two hiccups of the detector do not disqualify an element).
// - A view whose air is more than twice as noisy as the median view's, or whose level is more
//   than 3 sigma off, is an outlier (a dim or noisy frame): it certifies nothing. The levels of
//   the others are taken off their readings.
// - Each element's offset is the median of the low cluster of its level-corrected readings (those
//   within 4 sigma of its third lowest: the two lowest may be spikes), when at least 3 readings
//   form it, it lies in the band, and it is not above what the detector's stripes give for
//   that element by more than their error allows. The stripes' offset: the air's level plus
//   the element's mean over the views less a low quantile of its neighbours' means (plus that
//   quantile's usual distance below their median): the mean of a projection over the views is
//   smooth across elements, so the object cancels. An element that never sees past the object
//   (the middle of a wide sample) has its lowest readings at the object's thinnest projection:
//   an offset taken from them (the carving before issue 29) certified a faint object as air,
//   and carved a third of a square away. The low quantile, not the median: beside the object's
//   shadow the neighbours' means are partly object, and a median would take the elements there
//   for never seeing air.
// - A reading certifies air when the mean excess over their offsets of it and its two
//   neighbours along the detector row is below `sigmas` noise sigmas of such a mean, measured
//   as such on the air elements (a real detector's noise is correlated between neighbours: on
//   the shared real scans the mean of three is 0.66-0.85 as noisy as one reading, not 0.58). Three
//   rays are evidence a single one is not: at the same odds against noise the threshold is lower,
//   so object that grazing rays see below it is thinner.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "riner/scan.hpp"

namespace riner::model {

struct AirReadings {
  bool usable = false;  // false: too little air to trust (note says why); nothing certified
  std::string note;
  std::size_t air_elements = 0;     // elements that read air in every view
  double air_offset_median = 0.0;   // their readings' typical level (-ln alpha; 0 when flat)
  double noise = 0.0;               // the median view's air noise sigma (rho units)
  std::size_t per_view = 0;         // elements per view
  std::vector<double> view_level;   // per view: its air's level over the elements' own
  std::vector<double> view_noise;   // per view: its air's noise sigma
  std::vector<double> view_noise3;  // per view: the noise sigma of a mean of three neighbours
  std::vector<std::uint8_t> outlier_view;
  std::size_t outlier_views = 0;
  std::vector<double> offset;     // per element; NaN: it certifies nothing
  double stripe_tolerance = 0.0;  // how far above its stripe offset an offset may lie
  std::size_t above_stripes = 0;  // elements whose low readings lie further: they never see air

  // The mean excess of reading (view, element) and its row neighbours over their offsets, in
  // noise sigmas of that mean; NaN when unknown (an outlier view, no offset, no finite reading).
  double excess_sigmas(const Scan& scan, std::size_t view, std::size_t element) const;
  // The same excess in rho units (NaN when unknown).
  double excess(const Scan& scan, std::size_t view, std::size_t element) const;
  // Per reading [views][elements]: excess_sigmas < sigmas.
  std::vector<std::uint8_t> certified(const Scan& scan, double sigmas) const;

 private:
  // excess(), and into `used` how many readings it averaged (3, fewer at a row's end or beside
  // a reading without an offset).
  double mean_excess(const Scan& scan, std::size_t view, std::size_t element, int& used) const;
};

AirReadings read_air(const Scan& scan, double noise_sigmas);

}  // namespace riner::model
