// Host side of kernels/line_filter.cl: a convolution along the lines of a device array (the rows
// or the columns of a block of it), by FFT: in local memory where a padded line fits it, else in
// a global scratch buffer (the direct convolution, n^2 a line, stays for the tests).
#pragma once

#include <vector>

#include "cl/buffer.hpp"
#include "cl/program.hpp"

namespace riner::ops {

// Where the lines are: line l's value i at first + l * line_step + i * stride.
struct LineLayout {
  std::size_t lines = 0;
  std::size_t first = 0;
  std::size_t line_step = 0;
  std::size_t stride = 1;
};

// The taps (2 n - 1, tap d = j - j' at index d + n - 1) of the circular filter of period n whose
// gain at DFT bin k is gain[k] (gain[k] == gain[n - k], so that the filter is real).
std::vector<double> circular_filter_taps(const std::vector<double>& gain);

class LineFilterOp {
 public:
  // Lines of n values convolved with taps (2 n - 1 of them, as circular_filter_taps gives).
  LineFilterOp(cl::Context& context, std::size_t n, const std::vector<double>& taps);

  // out's lines = in's lines convolved with the taps; the rest of out is left as it was. in and
  // out are distinct buffers.
  void run(const cl::Buffer<float>& in, cl::Buffer<float>& out, const LineLayout& layout);
  enum class Path { kLocalFft, kGlobalFft, kDirect };
  Path path() const { return path_; }
  // Whether run() goes by FFT in local memory (what fits does unless `use` chose otherwise).
  bool by_fft() const { return path_ == Path::kLocalFft; }
  // The tests' way to run every path on one device; `groups` > 0 holds the global FFT to that
  // many work-groups (each then filters several pairs of lines).
  void use(Path path, std::size_t groups = 0) {
    path_ = path;
    global_groups_ = groups;
  }

 private:
  cl::Context& context_;
  cl_uint n_;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel direct_;
  cl::Kernel fft_;
  cl::Kernel fft_global_;
  cl::Buffer<float> taps_;
  Path path_ = Path::kLocalFft;
  std::size_t global_groups_ = 0;   // 0: as many as fill a device
  cl_uint fft_size_ = 0;            // the padded line's length
  cl::Buffer<cl_float2> spectrum_;  // the taps', bit-reversed, over fft_size_
  cl::Buffer<cl_float2> twiddles_;
  cl::Buffer<cl_float2> scratch_;  // kGlobalFft: fft_size_ per work-group, made on first use
};

}  // namespace riner::ops
