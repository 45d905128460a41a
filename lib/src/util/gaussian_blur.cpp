#include "util/gaussian_blur.hpp"

#include <algorithm>
#include <cmath>

#include "util/parallel.hpp"

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
  std::vector<float> in = data, out(data.size());
  std::size_t stride = 1;
  for (std::size_t axis = shape.size(); axis-- > 0;) {
    const long n = static_cast<long>(shape[axis]);
    const std::size_t lines = data.size() / static_cast<std::size_t>(n);
    parallel_for(lines, [&](std::size_t begin, std::size_t end) {
      for (std::size_t line = begin; line < end; ++line) {
        // The line's first voxel: `line` counts the other axes, this one's stride left out.
        const std::size_t base =
            (line / stride) * stride * static_cast<std::size_t>(n) + line % stride;
        for (long i = 0; i < n; ++i) {
          double sum = 0.0;
          for (long d = -reach; d <= reach; ++d) {
            const long j = std::clamp(i + d, 0L, n - 1);
            sum += w[static_cast<std::size_t>(d + reach)] *
                   in[base + static_cast<std::size_t>(j) * stride];
          }
          out[base + static_cast<std::size_t>(i) * stride] = static_cast<float>(sum);
        }
      }
    });
    std::swap(in, out);
    stride *= static_cast<std::size_t>(n);
  }
  return in;
}

}  // namespace riner::util
