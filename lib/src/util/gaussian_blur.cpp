#include "util/gaussian_blur.hpp"

#include <algorithm>
#include <cmath>

#include "util/along_each_axis.hpp"

namespace riner::util {

std::vector<float> gaussian_blur(const std::vector<float>& data,
                                 const std::vector<std::size_t>& shape, double sigma_px) {
  if (!(sigma_px > 0.0)) return data;
  const long reach = static_cast<long>(std::ceil(3.0 * sigma_px));
  std::vector<double> w(static_cast<std::size_t>(2 * reach + 1));
  double total = 0.0;
  for (long d = -reach; d <= reach; ++d) {
    w[static_cast<std::size_t>(d + reach)] = std::exp(-0.5 * d * d / (sigma_px * sigma_px));
    total += w[static_cast<std::size_t>(d + reach)];
  }
  for (double& v : w) v /= total;
  return along_each_axis(
      data, shape, [&](const float* in, float* out, std::size_t size, std::size_t stride) {
        const long n = static_cast<long>(size);
        for (long i = 0; i < n; ++i) {
          double sum = 0.0;
          for (long d = -reach; d <= reach; ++d) {
            const long j = std::clamp(i + d, 0L, n - 1);
            sum +=
                w[static_cast<std::size_t>(d + reach)] * in[static_cast<std::size_t>(j) * stride];
          }
          out[static_cast<std::size_t>(i) * stride] = static_cast<float>(sum);
        }
      });
}

}  // namespace riner::util
