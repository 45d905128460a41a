#include "ops/line_filter.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <unsupported/Eigen/FFT>

#include "riner/error.hpp"

namespace riner::ops {

namespace {

// The padded line's length for the FFT: a power of two >= 2 n - 1, so that the circular
// convolution of the zero-padded line is the linear one.
std::size_t fft_length(std::size_t n) {
  std::size_t length = 2;
  while (length < 2 * n - 1) length *= 2;
  return length;
}

std::size_t bit_reversed(std::size_t k, std::size_t n) {
  std::size_t r = 0;
  for (std::size_t bit = 1; bit < n; bit *= 2) r = (r << 1) | ((k & bit) ? 1 : 0);
  return r;
}

// The taps' spectrum over n_fft (tap d = j - j' at index d mod n_fft), bit-reversed, / n_fft.
std::vector<cl_float2> taps_spectrum(const std::vector<double>& taps, std::size_t n,
                                     std::size_t n_fft) {
  std::vector<std::complex<double>> circular(n_fft);
  for (std::size_t i = 0; i < taps.size(); ++i) {
    const long d = static_cast<long>(i) - static_cast<long>(n - 1);
    circular[static_cast<std::size_t>((d + static_cast<long>(n_fft)) % static_cast<long>(n_fft))] =
        taps[i];
  }
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> spectrum;
  fft.fwd(spectrum, circular);
  std::vector<cl_float2> out(n_fft);
  for (std::size_t k = 0; k < n_fft; ++k) {
    const std::complex<double> s = spectrum[bit_reversed(k, n_fft)] / static_cast<double>(n_fft);
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

// The work-group of the FFT filter: up to 256 work-items, half the padded line at most.
constexpr std::size_t kFftGroup = 256;
// The global-memory FFT's work-groups: a few per compute unit of a large GPU (132 on an H100).
constexpr std::size_t kGlobalFftGroups = 512;

}  // namespace

std::vector<double> circular_filter_taps(const std::vector<double>& gain) {
  const std::size_t n = gain.size();
  if (n == 0) throw Error("circular_filter_taps: no gains");
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> spectrum(gain.begin(), gain.end());
  std::vector<std::complex<double>> kernel;
  fft.inv(kernel, spectrum);  // h[m] = (1/n) sum_k gain[k] e^{2 pi i k m / n}
  std::vector<double> taps(2 * n - 1);
  for (std::size_t i = 0; i < taps.size(); ++i) {
    const long d = static_cast<long>(i) - static_cast<long>(n - 1);
    taps[i] = kernel[static_cast<std::size_t>((d + static_cast<long>(n)) % static_cast<long>(n))].real();
  }
  return taps;
}

LineFilterOp::LineFilterOp(cl::Context& context, std::size_t n, const std::vector<double>& taps)
    : context_(context),
      n_(static_cast<cl_uint>(n)),
      program_(context.program({"line_filter"})),
      direct_(*program_, "line_filter_direct"),
      fft_(*program_, "line_filter_fft"),
      fft_global_(*program_, "line_filter_fft_global") {
  if (n == 0 || taps.size() != 2 * n - 1) throw Error("line_filter: taps do not match the line");
  const std::vector<float> taps_f(taps.begin(), taps.end());
  taps_ = cl::Buffer<float>(context, std::span<const float>(taps_f));
  const std::size_t n_fft = fft_length(n);
  fft_size_ = static_cast<cl_uint>(n_fft);
  spectrum_ =
      cl::Buffer<cl_float2>(context, std::span<const cl_float2>(taps_spectrum(taps, n, n_fft)));
  twiddles_ = cl::Buffer<cl_float2>(context, std::span<const cl_float2>(fft_twiddles(n_fft)));
  // In local memory where the padded line fits (a GPU's 48 KiB: lines up to 2048).
  path_ = n_fft * sizeof(cl_float2) + 1024 <= context.info().local_mem_bytes ? Path::kLocalFft
                                                                             : Path::kGlobalFft;
}

void LineFilterOp::run(const cl::Buffer<float>& in, cl::Buffer<float>& out,
                       const LineLayout& layout) {
  if (layout.lines == 0) return;
  const std::size_t last = layout.first + (layout.lines - 1) * layout.line_step +
                           (static_cast<std::size_t>(n_) - 1) * layout.stride;
  if (last >= in.size() || last >= out.size() || in.get() == out.get()) {
    throw Error("line_filter: the lines run past a buffer, or in and out are one buffer");
  }
  const auto lines = static_cast<cl_uint>(layout.lines), first = static_cast<cl_uint>(layout.first),
             line_step = static_cast<cl_uint>(layout.line_step),
             stride = static_cast<cl_uint>(layout.stride);
  if (path_ == Path::kDirect) {
    const cl_uint n_out = lines * n_;
    direct_.set_args(n_out, static_cast<cl_int>(n_), first, line_step, stride, taps_, in, out);
    context_.launch(direct_, n_out);
    return;
  }
  cl::Kernel& kernel = path_ == Path::kLocalFft ? fft_ : fft_global_;
  const std::size_t group = std::min({kFftGroup, static_cast<std::size_t>(fft_size_) / 2,
                                      kernel.max_work_group_size(context_.device())});
  const std::size_t pairs = (layout.lines + 1) / 2;
  if (path_ == Path::kLocalFft) {
    fft_.set_args(lines, n_, first, line_step, stride, fft_size_, spectrum_, twiddles_, in, out,
                  cl::LocalMemory{fft_size_ * sizeof(cl_float2)});
    context_.launch(fft_, cl::Range(pairs * group), cl::Range(group));
    return;
  }
  // Enough work-groups to fill a device, each with its own line of scratch (64 MiB at most).
  const std::size_t line_bytes = fft_size_ * sizeof(cl_float2);
  const std::size_t groups = std::max<std::size_t>(
      1, std::min({pairs, global_groups_ > 0 ? global_groups_ : kGlobalFftGroups,
                   (64u << 20) / line_bytes}));
  if (scratch_.size() < groups * fft_size_)
    scratch_ = cl::Buffer<cl_float2>(context_, groups * fft_size_);
  fft_global_.set_args(lines, n_, first, line_step, stride, fft_size_, spectrum_, twiddles_, in,
                       out, scratch_);
  context_.launch(fft_global_, cl::Range(groups * group), cl::Range(group));
}

}  // namespace riner::ops
