// No-reference quality of a reconstruction, against the FBP of the same scan: what a user
// without a ground truth can check (issue 13). Every measure is about the rotation axis at the
// grid centre, inside the inscribed disc; of a volume, over its axial slices (the centre
// deviation only in 2D).
//   ring index   riner::ring_index (metrics.hpp)
//   specks       pixels above or below all 8 neighbours whose difference from their 3 x 3
//                median exceeds 6 noise sigmas, per 10^4 pixels of the disc; sigma is the FBP's
//                pixel noise (1.4826 x the median absolute difference of the FBP from its own
//                3 x 3 median). A pixel on an edge's slope lies between its neighbours and is
//                not a speck, however far its median jumps
//   centre       the largest difference, within `radius_px` of the axis, between the broad
//                radial profiles (angular means smoothed over radius) of the image and of the
//                FBP, against the FBP profile's own noise there (the rms of its angular means
//                about their smoothed version): a disc or dip at the centre that FBP does not
//                show stands out as more than one such sigma
//   edges        the 99th percentile of the gradient magnitude inside the disc (Sobel after a
//                Gaussian of 1 px, so that pixel noise does not pass for edges), of the image and
//                of the FBP: well below the FBP's, the image is blurred. Where the FBP's pixel
//                noise hides its edges at 1 px (its 99th percentile under 10 times its median),
//                both are measured after the same wider Gaussian, 2, 4 or 8 px, the first at
//                which the FBP's edges stand out (edge_scale_px). Fewer specks and rings can come
//                from blur alone (docs/history/RESULTS.md), so these read beside it
//   lost object  the share of the disc where the FBP clearly sees object and the image shows air
//                (issue 29): both blurred by a Gaussian of 2 px; the FBP's air level and noise
//                are the median and MAD of its blurred values where the image reads air (below
//                a tenth of its 99.5th percentile); object is over 5 of those sigmas, and air
//                in the image is less than a quarter of what the FBP shows there; only inside
//                the field every view sees, when it is given (FBP's bright rim at its edge is
//                not object). A lost region that is a thin arc about the axis (5.5 px wide at
//                most at half its peak, 4 times as long) is counted apart, as arcs: a ring of the
//                FBP the image has not, or a thin concentric structure taken for one; read them
//                with the PNG pair
#pragma once

#include <limits>

#include "riner/array.hpp"
#include "riner/geometry.hpp"

namespace riner {

// The FBP's pixel noise as the speck measure uses it (1/mm).
double residual_noise(const Array& image);

// Specks per 10^4 pixels of the inscribed disc, at 6 sigma of `noise`.
double specks_per_10k(const Array& image, double noise);

struct CentreDeviation {
  int radius_px = 20;
  double deviation = 0.0;  // largest |broad(image) - broad(fbp)| within radius_px (1/mm)
  double at_px = 0.0;      // where
  double fbp_noise = 0.0;  // rms of the FBP's angular means about their broad profile (1/mm)
  double sigmas = 0.0;     // deviation / fbp_noise
};

// The 99th percentile of |gradient| (1/mm per pixel) inside the inscribed disc after a Gaussian
// of smoothing_px, of each axial slice of a volume together.
double edge_strength(const Array& image, double smoothing_px = 1.0);

// The smallest Gaussian (1, 2, 4 or 8 px) at which the FBP's edges stand out of its noise: the
// 99th percentile of its gradient at least 10 times the median; 8 when none does.
double edge_scale_px(const Array& fbp);

// Below this fraction of the FBP's edge strength an image reads as blurred: the shared real scans
// give 0.92-1.01 at the defaults and 0.40-0.76 after 2000 steps (docs/history/RESULTS.md).
constexpr double kSoftEdgeRatio = 0.8;

CentreDeviation centre_deviation(const Array& image, const Array& fbp, int radius_px = 20,
                                 double smoothing_px = 3.0);

// Above this share of the disc, lost object is worth a look (a user trusts that what the image
// does not show was not there).
constexpr double kLostObjectShare = 1e-3;

struct LostObject {
  std::size_t pixels = 0;  // where the FBP sees object and the image air
  double share = 0.0;      // of the disc's pixels
  double fbp_noise = 0.0;  // the blurred FBP's noise sigma in the image's air (1/mm)
  // Of those, the ones in thin arcs about the axis (not in `pixels`): the FBP's rings the image
  // has not, or a thin concentric structure (a tube's wall) taken for a ring.
  std::size_t arc_pixels = 0;
  double arc_share = 0.0;
};

constexpr double kWholeDisc = std::numeric_limits<double>::infinity();

// Of a volume, over its axial slices together. `field_radius_px`: the radius, in pixels from the
// grid centre, of the field every view sees (riner::field_of_view); the lost object is looked
// for kFieldRimPx inside it.
LostObject lost_object(const Array& image, const Array& fbp, double field_radius_px = kWholeDisc);
constexpr double kFieldRimPx = 4.0;

struct QualityReport {
  double noise = 0.0;  // the FBP's pixel noise
  double ring_index = 0.0;
  double fbp_ring_index = 0.0;
  double specks_per_10k = 0.0;
  double fbp_specks_per_10k = 0.0;
  double edge_strength = 0.0;
  double fbp_edge_strength = 0.0;
  double edge_scale_px = 1.0;  // the Gaussian both edge strengths are measured after
  LostObject lost;
  CentreDeviation centre;
};

// The smallest side of an image (or a volume's slice) the report measures.
constexpr std::size_t kQualitySmallestSide = 16;

// InputError unless both are 2D images or volumes of the same shape, slices at least
// kQualitySmallestSide on a side.
// Of a volume, `centre` stays zero.
QualityReport quality_against_fbp(const Array& image, const Array& fbp,
                                  double field_radius_px = kWholeDisc);

// The field's radius in pixels of the reconstruction grid, for the above.
double field_radius_px(const Geometry& g);

}  // namespace riner
