// Ring corrections: steps after training that move rings from the image into the detector
// response, where the data cannot tell them apart.
//
// A ring centred on the rotation axis adds the same amount to every view of one detector
// element, exactly like a change of that element's response (docs/method.md, "Rings and the
// detector response"), so the data fit is the same for (image, alpha) and (image - G, alpha exp(-P G))
// for any rotationally symmetric image G with per-element projections P G. Training settles
// somewhere on that line; these steps pick a better point on it:
//
// - Air reference: for every radius whose circle crosses enough air (pixels well below the
//   object's values, away from its edges), the ring's value there is the median of the air
//   minus the image's overall air level. This sees rings of any width, only where there is air.
// - Radial gradient: inside the object, a ring changes the image by the same amount along its
//   whole circle, while anatomy's edges cross a circle at a few places. So the ring's slope at
//   radius r is the median, over the circle's flattest points (least change along the circle),
//   of the image's change from r to r + 1 pixel; summed outwards, minus its running median over
//   2 scale_px + 1 radii, it gives the narrow rings everywhere. Broader rings, the image's mean
//   radial trend and steps (a disc's edge) are left alone: the median cannot tell them apart.
// - Detector response: a detector's responses differ element by element; they do not drift
//   together over dozens of neighbouring elements. So -ln(alpha)'s structure across the detector
//   broader than scale_px, beyond its mean, is taken for broad rings the training put into
//   alpha instead of the image: the rotationally symmetric profile whose projections best match
//   it (least squares, kept out of air) goes back into the image. This is the broad band the
//   radial gradient leaves. Rings can only make structure that is even about the axis, so the
//   correction needs the even part to stand out over the odd one (the responses' own level).
//
// - Mirror pairs: the other way round, objects centred on the axis (a tube's wall, a
//   cylindrical sample's edge) that training put into alpha go back into the image, where
//   -ln(alpha)'s even part stands out against its odd part (correct_rings_from_mirrors).
//
// The chain runs mirror pairs, air, gradient, response, then the gradient again
// (RingCorrectionConfig): the mirror step first gives back what training took from the object,
// the first gradient pass keeps the steps of broad structure, the response step takes the broad
// structure away, and the second pass sees the narrow rings that sat beside it.
//
// What the image-side corrections cannot see: an object that is itself rotationally symmetric
// about the axis (a sample holder, a container, a cylindrical sample's edge) looks exactly like a
// ring. Such an object would need a large change of the detector response to explain, far beyond
// the 1-2% that training leaves, so a correction whose mean change of ln(alpha) exceeds
// max_mean_response_change is not applied.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

#include "riner/array.hpp"
#include "riner/geometry.hpp"

namespace riner {

struct AirRingSettings {
  // Air: pixels below this fraction of the image's 99.5th percentile...
  double air_fraction = 0.03;
  // ...and at least this many pixels (|dx| + |dy|) from anything that is not air, so the
  // partial-volume pixels at the object's edge stay out.
  int erosion_px = 3;
  // ...and joined, through such pixels, to the grid's edge. Low-density material inside an
  // object (light wood within its denser growth rings, foam) falls below the fraction when
  // the object's densest parts set the percentile; taken for air it would be "corrected" to
  // air's level (docs/history/RESULTS.md, issue 13). Air pockets enclosed by the object are lost to
  // the measurement; the radial-gradient correction sees their rings.
  bool reaches_edge = true;
  // A radius (bins of half a pixel) is measured only when it has this many air pixels.
  int min_pixels = 8;
  // Gaussian smoothing of the measured ring profile across radius bins (sigma in bins; 0 off).
  double smoothing_bins = 2.0;
  // Largest mean |change of ln(alpha)| over the elements that is still taken for a ring.
  double max_mean_response_change = 0.03;
};

struct RingCorrection {
  // Whether image and alpha were changed: false when no radius was measured or the change of
  // the response was too large to be a ring (then both are the input).
  bool applied = false;
  Array image;  // the image minus the ring profile
  Array alpha;  // the responses with the ring's projections folded in: same data fit
  double mean_response_change = 0.0;  // mean |ln(alpha_new / alpha)| over the elements
  // Ring profile: value (1/mm) subtracted at radii bin * radius_step_mm; 0 where unmeasured.
  std::vector<double> profile;
  double radius_step_mm = 0.0;
  // Bins with enough air, enough samples on the circle, or a live element's ray through them.
  std::size_t measured_radii = 0;
  std::size_t air_pixels = 0;  // air reference: air pixels after erosion, in the final pass
  // Detector response: rms of -ln(alpha)'s broad structure even about the axis over the odd one.
  double even_to_odd = 0.0;
  // Mirror pairs: elements whose even structure stood out against the odd part's noise, and the
  // largest such excess in units of that noise.
  std::size_t elements_moved = 0;
  double largest_even_sigmas = 0.0;
  // Mirror pairs: the excess that counted (min_sigmas, or more on a large detector).
  double even_sigmas_needed = 0.0;
  // Mirror pairs: the distances from the axis (mm) of those elements' rays, where an object
  // centred on the axis stands; the radial gradient and the response step leave these radii
  // alone.
  std::vector<double> object_radii_mm;
  // Radial gradient: the running median's half width used (pixels); detector response: its
  // Gaussian's sigma. Both: the profile's radii left alone for the mirror pairs' objects.
  double scale_px = 0.0;
  std::size_t radii_kept_for_objects = 0;
};

// `image` on the 2D geometry's grid ([n_y, n_x]) and `alpha` with one value per detector
// element. Returns the input unchanged (applied = false) when the image has too little air, no
// positive values, non-finite values, or the rings found would change the response too much.
// Throws InputError for a 3D geometry or mismatched shapes.
RingCorrection correct_rings_from_air(const Array& image, const Array& alpha,
                                      const Geometry& geometry,
                                      const AirRingSettings& settings = {});

struct GradientRingSettings {
  // Rings narrower than this (the running median's half width, in pixels) are measured;
  // broader ones stay, as the image's own radial trends and steps do. 0: kScaleAt256Px on a
  // slice of up to 256 pixels a side, grown with the side beyond: the rings training leaves
  // span a share of the field, not a number of pixels (a 512² DeepLesion slice at 12 px
  // 42.8 dB, at 24 px 45.9; docs/history/RESULTS.md, issue 29). Nearer the axis than this, the
  // half width is the radius (kScaleAt256Px at least).
  static constexpr double kScaleAt256Px = 12.0;
  double scale_px = 0.0;
  // The half width used on a slice whose larger side is side_px.
  double scale_px_for(std::size_t side_px) const {
    if (scale_px > 0.0) return scale_px;
    return kScaleAt256Px * std::max(1.0, static_cast<double>(side_px) / 256.0);
  }
  // The fraction of each circle's points whose slopes enter the median: those with the least
  // change along the circle, where anatomy's edges are not.
  double flat_fraction = 0.5;
  // Largest mean |change of ln(alpha)| over the elements that is still taken for rings.
  double max_mean_response_change = 0.03;
};

// Same inputs and guarantees as correct_rings_from_air; the profile has one node per pixel of
// radius. Run it after the air reference (the air fixes broad rings where it can see them), and
// again after the response correction. The profile is 0 within the median's half width of
// object_radii_mm (the mirror pairs' objects centred on the axis: a cylinder's bright rim is
// no ring).
RingCorrection correct_rings_from_gradient(const Array& image, const Array& alpha,
                                           const Geometry& geometry,
                                           const GradientRingSettings& settings = {},
                                           const std::vector<double>& object_radii_mm = {});

struct ResponseRingSettings {
  // Structure of -ln(alpha) across the detector broader than this (sigma of a Gaussian over the
  // elements' distances from the axis, in pixels) is taken for rings.
  double scale_px = 24.0;
  // Air pixels (the air reference's rule: below air_fraction of the 99.5th percentile) hold the
  // profile at 0 with this weight per unit of a circle's air fraction, relative to the fit.
  double air_fraction = 0.03;
  double air_weight = 30.0;
  // Rings make only broad structure even about the axis (a ring projects the same at distance
  // d and -d); the responses' own broad structure is as odd as it is even. Applied only when
  // the even part's rms is at least this many times the odd part's.
  double min_even_to_odd = 1.5;
  // Largest mean |change of ln(alpha)| over the elements that is still taken for rings.
  double max_mean_response_change = 0.03;
};

// Same inputs and guarantees as correct_rings_from_air; `dead_elements` (flat indices) do not
// count: their alpha is not a response. The profile has one node per pixel of radius and is
// negative where the image gains. Run it after the other two (it is the broad band they leave),
// then the gradient correction again. Within scale_px of object_radii_mm (the mirror pairs'
// objects) the fit pulls the profile to 0 with the weight it gives a circle of air: the HTC
// disc's real rim was dimmed 0.6% there without it.
RingCorrection correct_rings_from_response(const Array& image, const Array& alpha,
                                           const Geometry& geometry,
                                           const std::vector<std::size_t>& dead_elements,
                                           const ResponseRingSettings& settings = {},
                                           const std::vector<double>& object_radii_mm = {});

struct MirrorRingSettings {
  // Gaussian smoothing across elements (sigma, in elements) of -ln(alpha)'s even and odd parts
  // before they are compared: a ray's neighbours see nearly the same object.
  double smoothing_elements = 1.0;
  // The odd part's noise is its robust spread over this many elements on either side.
  int window_elements = 25;
  // Even structure at least this many times that noise, where the odd part stays below it, is
  // an object on the axis; so many elements on either side go with it.
  double min_sigmas = 4.0;
  // ... or more where the detector is large: the threshold that the detector's noise alone
  // (normal) crosses at some judged element with at most this probability. A 2048-element
  // detector's noise crossed 4 sigmas by chance (a Shepp-Logan at 2048 columns: -3.1 dB).
  double max_false_alarm = 0.05;
  int grow_elements = 2;
  // Largest mean |change of ln(alpha)| over the elements still taken (a sanity bound: this
  // correction moves objects, which may be large).
  double max_mean_response_change = 1.0;
};

// The other way round: an object centred on the rotation axis (a tube's wall, a cylindrical
// sample's edge) that training put into alpha goes back into the image. A detector's own
// errors are as odd about the axis as they are even (each element errs alone), while anything
// rotationally symmetric in the image is even only. So where -ln(alpha)'s even part stands out
// against its odd part's local noise by min_sigmas while the odd part does not, the even part
// there is taken for an object: the rotationally symmetric profile whose projections match it
// (least squares; elsewhere held near no change) is added to the image and taken out of alpha,
// keeping the data fit. Elements without a mirror on the detector (an offset detector's far
// side) give no evidence. Same inputs and guarantees as correct_rings_from_response.
RingCorrection correct_rings_from_mirrors(const Array& image, const Array& alpha,
                                         const Geometry& geometry,
                                         const std::vector<std::size_t>& dead_elements,
                                         const MirrorRingSettings& settings = {});

}  // namespace riner
