// The radial primitives every ring measure shares: where each pixel lies on the radius axis
// about the rotation axis (the grid's centre), and Gaussian smoothing along that axis.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace riner::rings {

// How far a Gaussian reaches, in sigmas, wherever rings are smoothed (weights beyond are
// below 0.04% of the centre's).
constexpr double kGaussianReach = 4.0;

// Each pixel's distance from the grid's centre in units of `step_px` pixels: the profile
// nodes lie at whole multiples of the step.
class PixelRadii {
 public:
  PixelRadii(std::size_t ny, std::size_t nx, double step_px);

  std::size_t size() const { return radii_.size(); }
  double operator[](std::size_t pixel) const { return radii_[pixel]; }
  // The node nearest the pixel (for medians and means per radius: each pixel in one bin).
  std::size_t nearest(std::size_t pixel) const;
  // Linear interpolation: the pixel lies between node `lower` and lower + 1, `upper_weight`
  // of the way to the latter.
  struct Between {
    std::size_t lower;
    double upper_weight;
  };
  Between between(std::size_t pixel) const;
  // Nodes up to the farthest pixel's nearest one.
  std::size_t nearest_nodes() const;
  // The angular mean of `values` (one per pixel) at each of `nodes` nodes, each pixel weighing
  // on its two nodes as linear interpolation from them would (the adjoint of drawing a profile
  // into the pixels); 0 at a node no pixel reaches.
  std::vector<double> angular_means(const std::vector<float>& values, std::size_t nodes) const;

 private:
  std::vector<double> radii_;
};

// What lies beyond the first and last values.
enum class Ends {
  kCut,     // nothing: the weights left renormalise
  kMirror,  // the values mirrored about the end nodes (a radial profile is even about r = 0)
};

// Index j mirrored into 0..n-1 about the first and last nodes (Ends::kMirror).
std::ptrdiff_t mirrored(std::ptrdiff_t j, std::ptrdiff_t n);

// Whether `radius` lies within `reach` of one of `radii` (same unit).
bool within_reach(const std::vector<double>& radii, double radius, double reach);

// Gaussian smoothing (sigma in nodes) of regularly spaced values. With `use`, only the values
// it marks enter, renormalised, and the others come out 0.
std::vector<double> gaussian_smooth(const std::vector<double>& values, double sigma, Ends ends,
                                    const std::vector<char>* use = nullptr);

// The Gaussian's weights (sigma in the positions' unit, not normalised) at x of the irregular
// `positions` within reach, in position order; with `use`, only those it marks.
std::vector<std::pair<std::size_t, double>> gaussian_weights_at(
    const std::vector<double>& positions, double x, double sigma,
    const std::vector<char>* use = nullptr);

// The Gaussian-weighted mean (sigma in the positions' unit) at x of the values at irregular
// `positions` that `use` marks; NaN when none lies within reach.
double gaussian_mean_at(const std::vector<double>& positions, const std::vector<double>& values,
                        const std::vector<char>& use, double x, double sigma);

}  // namespace riner::rings
