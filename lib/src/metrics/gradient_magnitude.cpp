#include "metrics/gradient_magnitude.hpp"

#include <cmath>
#include <limits>

#include "util/gaussian_blur.hpp"

namespace riner::metrics {

std::vector<double> gradient_magnitude(const Array& image, double smoothing_px) {
  const Array a(image.shape, util::gaussian_blur(image.data, image.shape, smoothing_px));
  const std::size_t ny = a.shape[0], nx = a.shape[1];
  std::vector<double> out(a.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t i = 1; i + 1 < ny; ++i) {
    for (std::size_t k = 1; k + 1 < nx; ++k) {
      const double gx = (a(i - 1, k + 1) + 2.0 * a(i, k + 1) + a(i + 1, k + 1)) -
                        (a(i - 1, k - 1) + 2.0 * a(i, k - 1) + a(i + 1, k - 1));
      const double gy = (a(i + 1, k - 1) + 2.0 * a(i + 1, k) + a(i + 1, k + 1)) -
                        (a(i - 1, k - 1) + 2.0 * a(i - 1, k) + a(i - 1, k + 1));
      out[i * nx + k] = std::hypot(gx, gy) / 8.0;
    }
  }
  return out;
}

}  // namespace riner::metrics
