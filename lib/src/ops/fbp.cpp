#include "ops/fbp.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <unsupported/Eigen/FFT>

#include "riner/array.hpp"
#include "riner/error.hpp"

namespace riner::ops {

namespace {

std::vector<float> to_float(const std::vector<double>& v) { return {v.begin(), v.end()}; }

// The padded length of a line for the FFT filter: a power of two >= 2 n_u - 1, so that the
// circular convolution of the zero-padded line is the linear one.
std::size_t fft_length(std::size_t n_u) {
  std::size_t n = 2;
  while (n < 2 * n_u - 1) n *= 2;
  return n;
}

std::size_t bit_reversed(std::size_t k, std::size_t n) {
  std::size_t r = 0;
  for (std::size_t bit = 1; bit < n; bit *= 2) r = (r << 1) | ((k & bit) ? 1 : 0);
  return r;
}

// The taps' spectrum over n (tap d = j - j' at index d mod n), in bit-reversed order, / n.
std::vector<cl_float2> taps_spectrum(const std::vector<double>& taps, std::size_t n_u,
                                     std::size_t n) {
  std::vector<std::complex<double>> circular(n);
  for (std::size_t i = 0; i < taps.size(); ++i) {
    const long d = static_cast<long>(i) - static_cast<long>(n_u - 1);
    circular[static_cast<std::size_t>((d + static_cast<long>(n)) % static_cast<long>(n))] = taps[i];
  }
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> spectrum;
  fft.fwd(spectrum, circular);
  std::vector<cl_float2> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::complex<double> s = spectrum[bit_reversed(k, n)] / static_cast<double>(n);
    out[k] = {{static_cast<float>(s.real()), static_cast<float>(s.imag())}};
  }
  return out;
}

std::vector<cl_float2> fft_twiddles(std::size_t n) {
  std::vector<cl_float2> out(n / 2);
  for (std::size_t k = 0; k < n / 2; ++k) {
    const double angle = -2.0 * M_PI * static_cast<double>(k) / static_cast<double>(n);
    out[k] = {{static_cast<float>(std::cos(angle)), static_cast<float>(std::sin(angle))}};
  }
  return out;
}

// Slices a work-item of fbp_backproject_parallel takes (kParallelSlices in kernels/fbp.cl).
constexpr std::size_t kParallelSlices = 4;

// The work-group of the FFT filter: up to 256 work-items, half the padded line at most.
constexpr std::size_t kFftGroup = 256;

}  // namespace

FbpOp::FbpOp(cl::Context& context, const Geometry& geometry, const std::vector<double>& taps,
             const std::vector<double>& view_weights)
    : context_(context),
      geometry_(to_device(geometry)),
      divergent_(geometry.is_divergent()),
      views_(context, std::span<const cl_float2>(view_rotations(geometry))),
      taps_(context, std::span<const float>(to_float(taps))),
      view_weights_(context, std::span<const float>(to_float(view_weights))),
      n_samples_(ray_count(geometry)),
      slice_voxels_(static_cast<cl_uint>(geometry.volume_shape[geometry.volume_shape.size() - 1] *
                                         geometry.volume_shape[geometry.volume_shape.size() - 2])),
      n_slices_(static_cast<cl_uint>(geometry.is_3d() ? geometry.volume_shape[0] : 1)),
      program_(context.program({"common", "ray_geometry", "fbp"})),
      filter_(*program_, "fbp_filter"),
      filter_fft_(*program_, "fbp_filter_fft"),
      backproject_parallel_(*program_, "fbp_backproject_parallel"),
      backproject_parallel_one_(*program_, "fbp_backproject_parallel_one"),
      backproject_divergent_(*program_, "fbp_backproject_divergent"),
      backproject_divergent_one_(*program_, "fbp_backproject_divergent_one") {
  if (taps.size() != 2 * geometry.n_u - 1 || view_weights.size() != geometry.n_views()) {
    throw Error("fbp: taps or view weights do not match the geometry");
  }
  // By FFT where the padded line fits the local memory (a GPU's 48 KB: up to 2048 columns).
  const std::size_t n = fft_length(geometry.n_u);
  if (n * sizeof(cl_float2) + 1024 <= context.info().local_mem_bytes) {
    fft_size_ = static_cast<cl_uint>(n);
    spectrum_ = cl::Buffer<cl_float2>(context, std::span<const cl_float2>(
                                                   taps_spectrum(taps, geometry.n_u, n)));
    twiddles_ = cl::Buffer<cl_float2>(context, std::span<const cl_float2>(fft_twiddles(n)));
  }
}

void FbpOp::filter(const cl::Buffer<float>& in, cl::Buffer<float>& out) {
  if (in.size() != n_samples_ || out.size() != n_samples_) throw Error("fbp_filter: size mismatch");
  if (fft_size_ == 0) {
    filter_.set_args(n_samples_, static_cast<cl_int>(geometry_.n_u), taps_, in, out);
    context_.launch(filter_, n_samples_);
    return;
  }
  const auto n_u = static_cast<cl_uint>(geometry_.n_u);
  const cl_uint lines = n_samples_ / n_u;
  const std::size_t group =
      std::min({kFftGroup, static_cast<std::size_t>(fft_size_) / 2,
                filter_fft_.max_work_group_size(context_.device())});
  filter_fft_.set_args(lines, n_u, fft_size_, spectrum_, twiddles_, in, out,
                       cl::LocalMemory{fft_size_ * sizeof(cl_float2)});
  context_.launch(filter_fft_, cl::Range((lines + 1) / 2 * group), cl::Range(group));
}

void FbpOp::backproject(const cl::Buffer<float>& filtered, cl::Buffer<float>& volume,
                        std::size_t first_slice, std::size_t slice_step) {
  const std::size_t slices = volume.size() / slice_voxels_;
  if (filtered.size() != n_samples_ || volume.size() % slice_voxels_ != 0 || slices == 0 ||
      slice_step == 0 || first_slice + (slices - 1) * slice_step >= n_slices_) {
    throw Error("fbp_backproject: size mismatch");
  }
  // Blocks of kParallelSlices slices per work-item; one slice alone would compute the
  // block's others for nothing.
  const bool one = slices == 1;
  cl::Kernel& kernel = divergent_ ? (one ? backproject_divergent_one_ : backproject_divergent_)
                                  : (one ? backproject_parallel_one_ : backproject_parallel_);
  const std::size_t per_item = one ? 1 : kParallelSlices;
  const auto columns = static_cast<cl_uint>(slice_voxels_);
  const auto blocks = static_cast<cl_uint>((slices + per_item - 1) / per_item);
  kernel.set_args(columns * blocks, static_cast<cl_uint>(first_slice),
                  static_cast<cl_uint>(slice_step), static_cast<cl_uint>(slices), geometry_,
                  views_, view_weights_, filtered, volume);
  context_.launch(kernel, std::size_t{columns} * blocks);
}

}  // namespace riner::ops
