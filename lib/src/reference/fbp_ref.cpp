#include "reference/fbp_ref.hpp"

#include <cmath>
#include <complex>
#include <unsupported/Eigen/FFT>

#include "riner/array.hpp"
#include "riner/rays.hpp"
#include "util/parallel.hpp"

namespace riner::ref {

std::vector<double> fbp_filter(const std::vector<double>& in, std::size_t n_u,
                               const std::vector<double>& taps) {
  std::size_t padded = 1;
  while (padded < 2 * n_u) padded *= 2;
  // The taps as a circular kernel: lag k at index k mod padded.
  std::vector<double> kernel(padded, 0.0);
  for (long k = -static_cast<long>(n_u - 1); k <= static_cast<long>(n_u - 1); ++k) {
    kernel[static_cast<std::size_t>((k + static_cast<long>(padded)) % static_cast<long>(padded))] =
        taps[static_cast<std::size_t>(k + static_cast<long>(n_u) - 1)];
  }
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> kernel_spectrum;
  fft.fwd(kernel_spectrum, kernel);
  std::vector<double> out(in.size());
  const std::size_t lines = in.size() / n_u;
  util::parallel_for(lines, [&](std::size_t begin, std::size_t end) {
    Eigen::FFT<double> local_fft;
    std::vector<double> line(padded);
    std::vector<std::complex<double>> spectrum;
    std::vector<double> result;
    for (std::size_t l = begin; l < end; ++l) {
      std::fill(line.begin(), line.end(), 0.0);
      std::copy_n(in.begin() + static_cast<long>(l * n_u), n_u, line.begin());
      local_fft.fwd(spectrum, line);
      for (std::size_t m = 0; m < padded; ++m) spectrum[m] *= kernel_spectrum[m];
      local_fft.inv(result, spectrum);
      std::copy_n(result.begin(), n_u, out.begin() + static_cast<long>(l * n_u));
    }
  });
  return out;
}

std::vector<double> fbp_backproject(const Geometry& g, const std::vector<double>& filtered,
                                    const std::vector<double>& view_weights,
                                    std::size_t first_slice, std::size_t slice_step,
                                    std::size_t slices) {
  const std::size_t rank = g.volume_shape.size();
  const std::size_t nx = g.volume_shape[rank - 1];
  const std::size_t ny = g.volume_shape[rank - 2];
  const std::size_t nz = slices > 0 ? slices : (g.is_3d() ? g.volume_shape[0] : 1);
  const std::size_t rows = g.is_3d() ? g.n_v : 1;
  std::vector<double> cosines(g.n_views());
  std::vector<double> sines(g.n_views());
  for (std::size_t v = 0; v < g.n_views(); ++v) {
    cosines[v] = std::cos(g.angles[v]);
    sines[v] = std::sin(g.angles[v]);
  }
  auto sample = [&](std::size_t view, double u, double row) {
    const double fu = std::floor(u);
    const double fr = std::floor(row);
    const long j = static_cast<long>(fu);
    const long r = static_cast<long>(fr);
    double value = 0.0;
    for (long dr = 0; dr < 2; ++dr) {
      const long rr = r + dr;
      if (rr < 0 || rr >= static_cast<long>(rows)) continue;
      const double w_row = dr ? row - fr : 1.0 - (row - fr);
      const double* line = filtered.data() + (view * rows + static_cast<std::size_t>(rr)) * g.n_u;
      if (j >= 0 && j < static_cast<long>(g.n_u)) value += w_row * (1.0 - (u - fu)) * line[j];
      if (j + 1 >= 0 && j + 1 < static_cast<long>(g.n_u)) value += w_row * (u - fu) * line[j + 1];
    }
    return value;
  };
  std::vector<double> volume(nx * ny * nz);
  util::parallel_for(volume.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t index = begin; index < end; ++index) {
      const std::size_t k = index % nx;
      const std::size_t i = (index / nx) % ny;
      const std::size_t l = first_slice + index / (nx * ny) * slice_step;
      const Vec3 p =
          voxel_centre(g, static_cast<double>(k), static_cast<double>(i), static_cast<double>(l));
      double sum = 0.0;
      for (std::size_t v = 0; v < g.n_views(); ++v) {
        const double a = p.x * cosines[v] + p.y * sines[v];
        const double b = -p.x * sines[v] + p.y * cosines[v];
        double scale = 1.0;
        double weight = view_weights[v];
        if (g.is_divergent()) {
          const double distance = g.source_origin_mm + b;
          scale = (g.source_origin_mm + g.origin_detector_mm) / distance;
          weight *= std::pow(g.source_origin_mm / distance, 2);
        }
        const double u = a * scale / g.pitch_u + 0.5 * (g.n_u - 1.0) - g.offset_u;
        const double row = g.is_3d() ? (p.z + g.grid_centre_z_mm) * scale / g.pitch_v +
                                           0.5 * (g.n_v - 1.0) - g.offset_v
                                     : 0.0;
        sum += weight * sample(v, u, row);
      }
      volume[index] = sum;
    }
  });
  return volume;
}

}  // namespace riner::ref
