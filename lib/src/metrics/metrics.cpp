#include "riner/metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "metrics/gradient_magnitude.hpp"
#include "metrics/radial_profile.hpp"
#include "riner/error.hpp"
#include "riner/io.hpp"
#include "rings/radial.hpp"

namespace riner {

namespace {

constexpr int kWindow = 7;  // scikit-image's default win_size
constexpr double kK1 = 0.01;
constexpr double kK2 = 0.03;

// Mean over a kWindow-wide box along one axis of a [outer][n][inner] block, for the positions
// whose window lies inside (the rest are cropped away by SSIM anyway and left untouched).
void box_mean_axis(std::vector<double>& data, std::size_t outer, std::size_t n, std::size_t inner) {
  const int half = kWindow / 2;
  std::vector<double> line(n);
  for (std::size_t o = 0; o < outer; ++o) {
    for (std::size_t in = 0; in < inner; ++in) {
      double* base = data.data() + o * n * inner + in;
      for (std::size_t j = 0; j < n; ++j) line[j] = base[j * inner];
      for (std::size_t j = half; j + half < n; ++j) {
        double sum = 0.0;
        for (int k = -half; k <= half; ++k) sum += line[j + k];
        base[j * inner] = sum / kWindow;
      }
    }
  }
}

// The uniform filter over every axis (separable), valid away from the borders.
std::vector<double> box_mean(std::vector<double> data, const std::vector<std::size_t>& shape) {
  std::size_t outer = 1;
  std::size_t total = 1;
  for (std::size_t d : shape) total *= d;
  for (std::size_t axis = 0; axis < shape.size(); ++axis) {
    const std::size_t n = shape[axis];
    const std::size_t inner = total / outer / n;
    box_mean_axis(data, outer, n, inner);
    outer *= n;
  }
  return data;
}

void check_pair(const Array& image, const Array& reference) {
  if (image.shape != reference.shape) {
    throw InputError("cannot compare images of shapes " + shape_string(image.shape) + " and " +
                     shape_string(reference.shape));
  }
  if (image.rank() < 2 || image.rank() > 3) throw InputError("metrics take 2D or 3D images");
  for (std::size_t i = 0; i < image.size(); ++i) {
    if (!std::isfinite(image.data[i]) || !std::isfinite(reference.data[i])) {
      throw InputError("cannot compute metrics over NaN or infinite pixels");
    }
  }
}

double reference_range(const Array& reference, const Array* mask) {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (std::size_t i = 0; i < reference.size(); ++i) {
    if (mask != nullptr && mask->data[i] == 0.0f) continue;
    lo = std::min(lo, static_cast<double>(reference.data[i]));
    hi = std::max(hi, static_cast<double>(reference.data[i]));
  }
  return hi > lo ? hi - lo : 1.0;
}

// Mean SSIM over the cropped map (positions at least kWindow/2 from every border), restricted
// to the mask when given.
double ssim_mean(const Array& image, const Array& reference, const Array* mask, double range) {
  const std::size_t n = image.size();
  std::vector<double> x(image.data.begin(), image.data.end());
  std::vector<double> y(reference.data.begin(), reference.data.end());
  std::vector<double> xx(n), yy(n), xy(n);
  for (std::size_t i = 0; i < n; ++i) {
    xx[i] = x[i] * x[i];
    yy[i] = y[i] * y[i];
    xy[i] = x[i] * y[i];
  }
  const auto& shape = image.shape;
  const std::vector<double> ux = box_mean(x, shape);
  const std::vector<double> uy = box_mean(y, shape);
  const std::vector<double> uxx = box_mean(xx, shape);
  const std::vector<double> uyy = box_mean(yy, shape);
  const std::vector<double> uxy = box_mean(xy, shape);
  const double np = std::pow(static_cast<double>(kWindow), static_cast<double>(shape.size()));
  const double cov_norm = np / (np - 1.0);  // sample covariance
  const double c1 = (kK1 * range) * (kK1 * range);
  const double c2 = (kK2 * range) * (kK2 * range);
  const std::size_t half = kWindow / 2;
  for (std::size_t d : shape) {
    if (d < static_cast<std::size_t>(kWindow)) {
      throw InputError("SSIM needs every side to be at least 7 pixels");
    }
  }
  double sum = 0.0;
  std::size_t count = 0;
  std::vector<std::size_t> idx(shape.size());
  for (std::size_t i = 0; i < n; ++i) {
    std::size_t rest = i;
    bool inside = true;
    for (std::size_t a = shape.size(); a-- > 0;) {
      const std::size_t c = rest % shape[a];
      rest /= shape[a];
      inside = inside && c >= half && c + half < shape[a];
    }
    if (!inside || (mask != nullptr && mask->data[i] == 0.0f)) continue;
    const double vx = cov_norm * (uxx[i] - ux[i] * ux[i]);
    const double vy = cov_norm * (uyy[i] - uy[i] * uy[i]);
    const double vxy = cov_norm * (uxy[i] - ux[i] * uy[i]);
    const double s = ((2.0 * ux[i] * uy[i] + c1) * (2.0 * vxy + c2)) /
                     ((ux[i] * ux[i] + uy[i] * uy[i] + c1) * (vx + vy + c2));
    sum += s;
    ++count;
  }
  return count > 0 ? sum / static_cast<double>(count) : 0.0;
}

// A volume thinner than SSIM's window along its slices (a few slices of a stack): its axial
// slices' 2D SSIM, averaged, where the whole comparison failed before.
bool thin_volume(const std::vector<std::size_t>& shape) {
  return shape.size() == 3 && shape[0] < static_cast<std::size_t>(kWindow) &&
         shape[1] >= static_cast<std::size_t>(kWindow) &&
         shape[2] >= static_cast<std::size_t>(kWindow);
}

double slice_ssim_mean(const Array& image, const Array& reference, const Array* mask,
                       double range) {
  double sum = 0.0;
  for (std::size_t k = 0; k < image.shape[0]; ++k) {
    const Array m = mask != nullptr ? axial_slice(*mask, k) : Array();
    sum += ssim_mean(axial_slice(image, k), axial_slice(reference, k),
                     mask != nullptr ? &m : nullptr, range);
  }
  return sum / static_cast<double>(image.shape[0]);
}

}  // namespace

Array circle_mask(const std::vector<std::size_t>& shape, double fraction) {
  if (shape.size() < 2) throw InputError("a circle mask needs at least two axes");
  Array mask(shape, 0.0f);
  const std::size_t ny = shape[shape.size() - 2];
  const std::size_t nx = shape[shape.size() - 1];
  const double radius = fraction * 0.5 * static_cast<double>(std::min(nx, ny));
  const double cy = 0.5 * (ny - 1.0);
  const double cx = 0.5 * (nx - 1.0);
  for (std::size_t i = 0; i < mask.size(); ++i) {
    const double x = static_cast<double>(i % nx) - cx;
    const double y = static_cast<double>((i / nx) % ny) - cy;
    mask.data[i] = x * x + y * y <= radius * radius ? 1.0f : 0.0f;
  }
  return mask;
}

namespace {

constexpr double kEdgeSmoothingPx = 1.0;
constexpr double kEdgeQuantile = 0.999;
constexpr double kEdgeShareOfQuantile = 0.5;

// ImageMetrics::edge_ratio.
double edge_ratio(const Array& image, const Array& reference, const Array* mask) {
  const std::size_t rank = image.rank();
  if (rank != 2 && rank != 3) return 0.0;
  const std::size_t slices = rank == 3 ? image.shape[0] : 1;
  const std::size_t per_slice = image.size() / std::max<std::size_t>(1, slices);
  if (image.shape[rank - 2] < 3 || image.shape[rank - 1] < 3) return 0.0;
  std::vector<double> shown, truth;
  for (std::size_t z = 0; z < slices; ++z) {
    const std::vector<double> a =
        metrics::gradient_magnitude(rank == 3 ? axial_slice(image, z) : image, kEdgeSmoothingPx);
    const std::vector<double> r = metrics::gradient_magnitude(
        rank == 3 ? axial_slice(reference, z) : reference, kEdgeSmoothingPx);
    for (std::size_t p = 0; p < per_slice; ++p) {
      if (mask != nullptr && mask->data[z * per_slice + p] == 0.0f) continue;
      if (!std::isfinite(a[p]) || !std::isfinite(r[p]) || r[p] <= 0.0) continue;
      shown.push_back(a[p]);
      truth.push_back(r[p]);
    }
  }
  if (truth.empty()) return 0.0;
  std::vector<double> sorted = truth;
  const auto at = static_cast<long>(kEdgeQuantile * static_cast<double>(sorted.size() - 1));
  std::nth_element(sorted.begin(), sorted.begin() + at, sorted.end());
  const double threshold = kEdgeShareOfQuantile * sorted[static_cast<std::size_t>(at)];
  double sum_shown = 0.0, sum_truth = 0.0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    if (truth[i] < threshold) continue;
    sum_shown += shown[i];
    sum_truth += truth[i];
  }
  return sum_truth > 0.0 ? sum_shown / sum_truth : 0.0;
}

}  // namespace

ImageMetrics compare_images(const Array& image, const Array& reference, const Array* mask,
                            double data_range) {
  check_pair(image, reference);
  if (mask != nullptr && mask->shape != image.shape) {
    throw InputError("the mask's shape " + shape_string(mask->shape) +
                     " differs from the image's " + shape_string(image.shape));
  }
  ImageMetrics m;
  m.data_range = data_range > 0.0 ? data_range : reference_range(reference, mask);
  double abs_sum = 0.0;
  double sq_sum = 0.0;
  for (std::size_t i = 0; i < image.size(); ++i) {
    if (mask != nullptr && mask->data[i] == 0.0f) continue;
    const double d = static_cast<double>(image.data[i]) - reference.data[i];
    abs_sum += std::fabs(d);
    sq_sum += d * d;
    ++m.pixels;
  }
  if (m.pixels == 0) throw InputError("the mask selects no pixels");
  const double mse = sq_sum / static_cast<double>(m.pixels);
  m.mae = abs_sum / static_cast<double>(m.pixels);
  m.rmse = std::sqrt(mse);
  m.psnr = mse > 0.0 ? 10.0 * std::log10(m.data_range * m.data_range / mse)
                     : std::numeric_limits<double>::infinity();
  m.ssim = thin_volume(image.shape) ? slice_ssim_mean(image, reference, mask, m.data_range)
                                    : ssim_mean(image, reference, mask, m.data_range);
  m.edge_ratio = edge_ratio(image, reference, mask);
  return m;
}

namespace metrics {

void radial_means(const Array& image, std::size_t bins, std::vector<double>& mean,
                  std::vector<double>& count) {
  const rings::PixelRadii radii(image.shape[0], image.shape[1], 1.0);
  mean.assign(bins, 0.0);
  count.assign(bins, 0.0);
  for (std::size_t p = 0; p < image.size(); ++p) {
    const std::size_t r = radii.nearest(p);
    if (r >= bins || !std::isfinite(image.data[p])) continue;
    mean[r] += image.data[p];
    count[r] += 1.0;
  }
  for (std::size_t r = 0; r < bins; ++r) mean[r] = count[r] > 0 ? mean[r] / count[r] : 0.0;
}

}  // namespace metrics

namespace {

// Sum of squares of a 2D image's radial profile about its 7-bin running median, and the number
// of radii it sums over.
std::pair<double, std::size_t> ring_residual(const Array& image) {
  const auto bins =
      static_cast<std::size_t>(0.5 * static_cast<double>(std::min(image.shape[0], image.shape[1])));
  std::vector<double> mean, count;
  metrics::radial_means(image, bins, mean, count);
  // Radii no pixel centre rounds to (0 on an even grid) are left out, not taken as 0.
  std::vector<double> profile;
  for (std::size_t r = 0; r < bins; ++r) {
    if (count[r] > 0) profile.push_back(mean[r]);
  }
  double residual = 0.0;
  const std::size_t n = profile.size();
  for (std::size_t r = 0; r < n; ++r) {
    std::vector<double> window;
    for (std::size_t k = r >= 3 ? r - 3 : 0; k <= std::min(n - 1, r + 3); ++k)
      window.push_back(profile[k]);
    std::nth_element(window.begin(), window.begin() + static_cast<long>(window.size() / 2),
                     window.end());
    const double d = profile[r] - window[window.size() / 2];
    residual += d * d;
  }
  return {residual, n};
}

}  // namespace

double ring_index(const Array& image) {
  const std::size_t rank = image.rank();
  if (rank != 2 && rank != 3) throw InputError("the ring index takes a 2D image or a volume");
  if (std::min(image.shape[rank - 2], image.shape[rank - 1]) < 16 || image.size() == 0) {
    throw InputError("the ring index needs an image of at least 16 x 16");
  }
  double residual = 0.0;
  std::size_t n = 0;
  const std::size_t slices = rank == 3 ? image.shape[0] : 1;
  for (std::size_t z = 0; z < slices; ++z) {
    const auto [sum, radii] = ring_residual(rank == 3 ? axial_slice(image, z) : image);
    residual += sum;
    n += radii;
  }
  const Window w = percentile_window(image, 1.0, 99.0);
  return std::sqrt(residual / static_cast<double>(n)) /
         std::max(1e-12, static_cast<double>(w.hi - w.lo));
}

double psnr(const Array& image, const Array& reference, double data_range) {
  return compare_images(image, reference, nullptr, data_range).psnr;
}

double ssim(const Array& image, const Array& reference, double data_range) {
  return compare_images(image, reference, nullptr, data_range).ssim;
}

}  // namespace riner
