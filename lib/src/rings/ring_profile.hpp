// What every ring correction shares: a rotationally symmetric profile g(r) about the rotation
// axis is moved from the image into the detector response, alpha * exp(-P g), which keeps the
// data fit, unless the response would have to change more than a ring can explain.
#pragma once

#include <Eigen/Dense>
#include <cstddef>
#include <vector>

#include "riner/geometry.hpp"
#include "riner/ring_correction.hpp"

namespace riner::rings {

// The air rule's reference: the image's 99.5th percentile, its brightest object values
// without the odd hot pixel.
constexpr double kAirReferencePercentile = 0.995;
// Step of a ring's line integrals along a ray, in voxels: fine against the profile's nodes
// (one or half a voxel apart).
constexpr double kIntegralStepVoxels = 0.1;

// InputError (prefixed with `what`) for a 3D geometry, an image off the geometry's grid or an
// alpha with the wrong number of elements.
void check_inputs(const char* what, const Array& image, const Array& alpha, const Geometry& g);

// The input as it is (applied = false), with the profile's node spacing set.
RingCorrection unchanged(const Array& image, const Array& alpha, double radius_step_mm);

bool all_finite(const Array& image);

// The line integral of a piecewise-linear profile with `nodes` nodes (at index * step_mm)
// along detector element `element`'s ray (view 0: a ring is the same in every view), as one
// weight per node: the integral is their dot product with the profile.
std::vector<double> ring_projection_weights(std::size_t nodes, double step_mm, const Geometry& g,
                                            std::size_t element);
// That integral of `profile` for every element: what the ring adds to each element's readings.
std::vector<double> ring_projections(const std::vector<double>& profile, double step_mm,
                                     const Geometry& g);

// Each element's -ln(alpha) where it is a response: live (not in `dead`; an index beyond the
// detector is an InputError prefixed with `what`), alpha finite and above 1e-6 (below, ln would
// blow up); 0 elsewhere.
struct ResponseOffsets {
  std::vector<char> usable;
  std::vector<double> offset;
  std::size_t count = 0;  // usable elements
};
void check_dead_elements(const char* what, const std::vector<std::size_t>& dead, std::size_t n_u);
ResponseOffsets response_offsets(const Array& alpha, const std::vector<std::size_t>& dead);

// A profile's nodes for an image: one every `step_px` pixels of radius out to the farthest
// pixel, plus a spare; `solved` of them lie inside the grid's inscribed circle, beyond which the
// grid's corners cut a ring differently in every view (no longer a per-element offset).
struct ProfileNodes {
  std::size_t nodes = 0;
  Eigen::Index solved = 0;
};
ProfileNodes profile_nodes(const Array& image, double step_px = 1.0);

// The image gains `gain` (per solved node; `weights`: every element's projection weights on
// them): out.profile = -gain, folded into alpha (fold_into_alpha) and, when that is applied,
// subtracted from the image.
void move_gain_into_image(RingCorrection& out, const Array& image, const Geometry& g,
                          const Eigen::VectorXd& gain, const Eigen::MatrixXd& weights,
                          std::size_t nodes, double max_mean_response_change);

// The air rule of the corrections: pixels below fraction times kAirReferencePercentile's value.
// Returns that threshold (not positive when the image has no positive values).
double air_threshold(const Array& image, double fraction);

// out.image = image minus the profile, linearly interpolated at each pixel's distance from the
// axis (out.profile needs a spare last node).
void subtract_profile(RingCorrection& out, const Array& image, const Geometry& g);

// With out.alpha holding the input and `change` the profile's projection per element
// (ring_projections): sets out.mean_response_change, and when it is at most
// `max_mean_response_change`, folds the change into out.alpha and returns true. The caller
// subtracts the profile from the image only then.
bool fold_into_alpha(RingCorrection& out, const std::vector<double>& change,
                     double max_mean_response_change);

}  // namespace riner::rings
