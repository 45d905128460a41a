// Image quality against a ground truth (METHOD.md §5): PSNR, SSIM as scikit-image's
// structural_similarity defaults (7-wide uniform window, K1 = 0.01, K2 = 0.03, sample
// covariance, mean over the map with a 3-pixel border cropped), MAE, RMSE. 2D and 3D.
#pragma once

#include <optional>

#include "riner/array.hpp"

namespace riner {

struct ImageMetrics {
  double psnr = 0.0;  // dB
  double ssim = 0.0;
  double mae = 0.0;
  double rmse = 0.0;
  double data_range = 0.0;  // max - min of the reference (inside the mask when one is given)
  std::size_t pixels = 0;   // compared pixels
  // Sharpness against the reference: the image's gradient summed over the reference's
  // strongest edges over the reference's own there (1: as sharp; 0.7: a blurred edge). Both
  // after a Gaussian of 1 px, |Sobel| / 8, per axial slice of a volume; edges are where the
  // reference's gradient is at least half its 99.9th percentile. Noise in the image adds to
  // its gradient: compare images of like noise. 0 when the reference has no edge.
  double edge_ratio = 0.0;
};

// A mask (1 inside, 0 outside) of the disk, or cylinder in 3D, inscribed in the last two axes,
// of radius fraction * min(n_y, n_x) / 2 around the grid centre.
Array circle_mask(const std::vector<std::size_t>& shape, double fraction = 1.0);

// image and reference must have the same shape; a mask (same shape, nonzero = inside)
// restricts every metric, SSIM to the masked part of its cropped map. data_range <= 0 means
// max - min of the reference. InputError for mismatched shapes or non-finite values.
ImageMetrics compare_images(const Array& image, const Array& reference, const Array* mask = nullptr,
                            double data_range = 0.0);

double psnr(const Array& image, const Array& reference, double data_range = 0.0);

// How ringed an image is, without a reference (the measure in ../shared/data/*/SOURCE.md):
// the RMS over radius of the angular-mean radial profile about the grid centre (the rotation
// axis) minus its 7-pixel running median, divided by the image's 1st-99th percentile range.
// Radii up to the inscribed circle. Of a volume [z, y, x]: the RMS over every axial slice's
// radii (rings of a parallel or cone beam are circles in the slices), divided by the volume's
// range. Clean FBP of the DeepLesion simulations
// scores 0.003-0.006, ring-corrupted FBP 0.10-0.14.
double ring_index(const Array& image);
double ssim(const Array& image, const Array& reference, double data_range = 0.0);

}  // namespace riner
