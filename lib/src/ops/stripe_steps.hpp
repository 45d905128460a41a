// Host side of kernels/stripe_columns.cl and kernels/wavelet.cl: the steps of classical stripe
// removal on a sinogram held on the device, each a launch with its sizes checked against the
// buffers. destripe/device_destripe.cpp strings them into the methods.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "cl/buffer.hpp"
#include "cl/context.hpp"
#include "cl/program.hpp"
#include "ops/line_filter.hpp"

namespace riner::ops {

// The stripe filters' kernels as one program, which StripeStepsOp and StripeSortingOp share: a
// process builds it once (on PoCL every program built costs about 30 ms even from PoCL's cache).
const std::vector<std::string>& stripe_program_sources();

// stripe_columns.cl's FLUCTUATION_SPAN_MAX: column_fluctuation's ring of views.
constexpr std::size_t kFluctuationSpanMax = 8;

class StripeStepsOp {
 public:
  explicit StripeStepsOp(cl::Context& context);

  cl::Context& context() { return context_; }

  // means[c]: column c's mean over the views [from, to) of in [views][columns].
  void column_means(std::size_t views, std::size_t columns, std::size_t from, std::size_t to,
                    const cl::Buffer<float>& in, cl::Buffer<float>& means);
  // values[v][c] -= offsets[c].
  void subtract_column_offsets(std::size_t columns, const cl::Buffer<float>& offsets,
                               cl::Buffer<float>& values);
  // deviation[v][c]: the reading's distance from its moving mean over 2 half + 1 views.
  void view_deviations(std::size_t views, std::size_t columns, std::size_t half,
                       const cl::Buffer<float>& in, cl::Buffer<float>& deviation);
  // total[c]: column c's summed deviation; own[c]: the part of it beyond the largest deviation
  // of the columns c +- near..far within span (<= kFluctuationSpanMax) views.
  void column_fluctuation(std::size_t views, std::size_t columns, std::size_t near, std::size_t far,
                          std::size_t span, const cl::Buffer<float>& deviation,
                          cl::Buffer<float>& total, cl::Buffer<float>& own);
  // Where weight[c] >= 0, column c from its neighbours left[c] and right[c].
  void interpolate_columns(std::size_t columns, const cl::Buffer<cl_uint>& left,
                           const cl::Buffer<cl_uint>& right, const cl::Buffer<float>& weight,
                           cl::Buffer<float>& values);
  // values = source in the columns where mask is set.
  void replace_masked_columns(std::size_t columns, const cl::Buffer<cl_uchar>& mask,
                              const cl::Buffer<float>& source, cl::Buffer<float>& values);
  // values[v][c] += plus at (plus_first + v plus_stride + c) - minus at its like.
  void add_difference(std::size_t views, std::size_t columns, const cl::Buffer<float>& plus,
                      std::size_t plus_first, std::size_t plus_stride,
                      const cl::Buffer<float>& minus, std::size_t minus_first,
                      std::size_t minus_stride, cl::Buffer<float>& values);
  // trend = basis basis^T in along each column (basis [views][terms], orthonormal columns);
  // coefficients [terms][columns] is scratch.
  void polynomial_trend(std::size_t views, std::size_t columns, std::size_t terms,
                        const cl::Buffer<float>& basis, const cl::Buffer<float>& in,
                        cl::Buffer<float>& coefficients, cl::Buffer<float>& trend);
  // out [out_views][columns]: in from row pad on, mirrored about its first and last views.
  void reflect_pad_views(std::size_t views, std::size_t columns, std::size_t pad,
                         std::size_t out_views, const cl::Buffer<float>& in, cl::Buffer<float>& out);
  // out [out_views][out_columns]: in at its top left, continuous when wrapped.
  void periodic_extension(std::size_t views, std::size_t columns, std::size_t out_views,
                          std::size_t out_columns, const cl::Buffer<float>& in,
                          cl::Buffer<float>& out);
  // rows x columns values from src (first, stride) to dst (first, stride).
  void copy_block(std::size_t rows, std::size_t columns, const cl::Buffer<float>& src,
                  std::size_t src_first, std::size_t src_stride, cl::Buffer<float>& dst,
                  std::size_t dst_first, std::size_t dst_stride);
  // One level of the periodised wavelet transform along the lines (n values each, even), and
  // its inverse; h and g the low and high pass.
  void wavelet_analyse(const LineLayout& lines, std::size_t n, const cl::Buffer<float>& h,
                       const cl::Buffer<float>& g, const cl::Buffer<float>& in,
                       cl::Buffer<float>& out);
  void wavelet_synthesise(const LineLayout& lines, std::size_t n, const cl::Buffer<float>& h,
                          const cl::Buffer<float>& g, const cl::Buffer<float>& in,
                          cl::Buffer<float>& out);

 private:
  cl::Context& context_;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel column_means_, subtract_offsets_, deviations_, fluctuation_, interpolate_,
      replace_masked_, add_difference_, coefficients_, values_, reflect_pad_, periodic_,
      copy_block_, analyse_, synthesise_;
};

}  // namespace riner::ops
