#include "rings/ring_settings.hpp"

#include <string>

#include "riner/error.hpp"

namespace riner::rings {

using settings::closed;
using settings::field;
using settings::open;
using settings::open_closed;

const std::vector<settings::Setting<AirRingSettings>>& air_settings() {
  using S = AirRingSettings;
  static const std::vector<settings::Setting<S>> table = {
      field<S>("rings", "air_fraction", open(0, 1),
               "air: pixels below this fraction of the image's 99.5th percentile",
               &S::air_fraction),
      field<S>("rings", "air_erosion_px", closed(0, 64),
               "air pixels this far (|dx|+|dy|) from anything that is not air", &S::erosion_px),
      field<S>("rings", "air_reaches_edge", {},
               "air correction: only air joined to the grid's edge (not low-density material "
               "inside the object)",
               &S::reaches_edge),
      field<S>("rings", "min_air_pixels", closed(1, 1 << 20),
               "air pixels a radius bin needs to be measured", &S::min_pixels),
      field<S>("rings", "max_mean_response_change", open_closed(0, 10),
               "air correction: largest mean |change of ln alpha| still taken for rings",
               &S::max_mean_response_change),
      field<S>("rings", "smoothing_bins", closed(0, 100),
               "air correction: Gaussian smoothing of the measured profile, in radius bins",
               &S::smoothing_bins),
  };
  return table;
}

const std::vector<settings::Setting<GradientRingSettings>>& gradient_settings() {
  using S = GradientRingSettings;
  static const std::vector<settings::Setting<S>> table = {
      field<S>(
          "rings", "gradient_scale_px", closed(0, 1000),
          "gradient correction: rings narrower than this (pixels; half the running median) are "
          "measured; 0: 12 on slices up to 256 px a side, grown with the side beyond (24 at "
          "512)",
          &S::scale_px),
      field<S>("rings", "gradient_flat_fraction", open_closed(0, 1),
               "gradient correction: fraction of each circle's flattest points in the median",
               &S::flat_fraction),
      field<S>("rings", "gradient_max_mean_response_change", open_closed(0, 10),
               "gradient correction: largest mean |change of ln alpha| still taken for rings",
               &S::max_mean_response_change),
  };
  return table;
}

const std::vector<settings::Setting<ResponseRingSettings>>& response_settings() {
  using S = ResponseRingSettings;
  static const std::vector<settings::Setting<S>> table = {
      field<S>("rings", "response_scale_px", open_closed(0, 1000),
               "response correction: -ln alpha structure broader than this (pixels) is rings",
               &S::scale_px),
      field<S>("rings", "response_air_fraction", open(0, 1),
               "response correction: air rule, as rings.air_fraction", &S::air_fraction),
      field<S>("rings", "response_air_weight", closed(0, 1e6),
               "response correction: weight holding the profile at 0 in air", &S::air_weight),
      field<S>("rings", "response_min_even_to_odd", closed(0, 1e6),
               "response correction: applied when the even structure's rms is this many times "
               "the odd's",
               &S::min_even_to_odd),
      field<S>("rings", "response_max_mean_response_change", open_closed(0, 10),
               "response correction: largest mean |change of ln alpha| still taken for rings",
               &S::max_mean_response_change),
  };
  return table;
}

const std::vector<settings::Setting<MirrorRingSettings>>& mirror_settings() {
  using S = MirrorRingSettings;
  static const std::vector<settings::Setting<S>> table = {
      field<S>("rings", "mirror_smoothing_elements", closed(0, 100),
               "mirror correction: Gaussian smoothing of -ln alpha's even and odd parts, in "
               "elements",
               &S::smoothing_elements),
      field<S>("rings", "mirror_window_elements", closed(1, 10000),
               "mirror correction: elements on either side that set the odd part's noise",
               &S::window_elements),
      field<S>("rings", "mirror_min_sigmas", open_closed(0, 1000),
               "mirror correction: even structure this many times the odd noise is an object on "
               "the axis",
               &S::min_sigmas),
      field<S>("rings", "mirror_max_false_alarm", open_closed(0, 1),
               "mirror correction: largest chance that the detector's noise alone passes for an "
               "object somewhere on it (raises mirror_min_sigmas on large detectors)",
               &S::max_false_alarm),
      field<S>("rings", "mirror_grow_elements", closed(0, 1000),
               "mirror correction: elements on either side taken with such structure",
               &S::grow_elements),
      field<S>("rings", "mirror_max_mean_response_change", open_closed(0, 10),
               "mirror correction: largest mean absolute change of ln alpha still applied",
               &S::max_mean_response_change),
  };
  return table;
}

namespace {

template <typename S>
void check(const char* what, const S& s, const std::vector<settings::Setting<S>>& table) {
  const std::string problem = settings::first_violation(s, table);
  if (!problem.empty()) throw InputError(std::string(what) + ": " + problem);
}

}  // namespace

void validate(const char* what, const AirRingSettings& s) { check(what, s, air_settings()); }
void validate(const char* what, const GradientRingSettings& s) {
  check(what, s, gradient_settings());
}
void validate(const char* what, const ResponseRingSettings& s) {
  check(what, s, response_settings());
}
void validate(const char* what, const MirrorRingSettings& s) { check(what, s, mirror_settings()); }

}  // namespace riner::rings
