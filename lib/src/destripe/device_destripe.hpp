// The classical stripe-removal methods with every per-reading step on an OpenCL device
// (ops/stripe_steps, ops/stripe_sorting, ops/line_filter) and the small per-column decisions
// (stripe_rules.hpp) on the host, as destripe.cpp's CPU path takes them: the same method, step
// for step, in float where the CPU twin is in double.
#pragma once

#include <memory>
#include <vector>

#include "cl/buffer.hpp"
#include "cl/context.hpp"
#include "destripe/sinogram_ops.hpp"
#include "destripe/stripe_rules.hpp"
#include "ops/line_filter.hpp"
#include "ops/stripe_sorting.hpp"
#include "ops/stripe_steps.hpp"
#include "riner/destripe.hpp"

namespace riner::stripes {

class DeviceDestripe {
 public:
  // Whether the device can run `method`: for the methods that sort, whether it holds a column
  // of `views` readings in local memory, at the settings' windows.
  static bool supported(const cl::Context& context, DestripeMethod method, std::size_t views,
                        const StripeSettings& settings);

  // Buffers and filters for sinograms of views x columns.
  DeviceDestripe(cl::Context& context, DestripeMethod method, const StripeSettings& settings,
                 std::size_t views, std::size_t columns);

  // A views x columns sinogram destriped in place; the masks of dead and large stripes where
  // the method finds them.
  void run(std::vector<float>& values, std::vector<bool>& dead, std::vector<bool>& large);

 private:
  void normalise();
  void filtering();
  void fitting();
  void wavelet();
  std::vector<bool> large_stripes();
  std::vector<bool> dead_stripes();
  std::vector<double> read_columns(const cl::Buffer<float>& buffer);
  void write_columns(cl::Buffer<float>& buffer, const std::vector<double>& values);

  cl::Context& context_;
  DestripeMethod method_;
  StripeSettings settings_;
  std::size_t views_, columns_;
  ops::StripeStepsOp steps_;
  std::unique_ptr<ops::StripeSortingOp> sorting_;
  cl::Buffer<float> values_, work_, column_a_, column_b_;
  // filtering: the padded columns and their low-pass, and the sorted smooth part (work2_);
  // fitting: the basis, its coefficients, and the trend's extension and its low-pass; wavelet:
  // the padded array and its scratch.
  cl::Buffer<float> work2_, padded_, padded2_, basis_, coefficients_, low_pass_, high_pass_;
  std::size_t pad_ = 0, terms_ = 0, wide_views_ = 0, wide_columns_ = 0;
  std::unique_ptr<ops::LineFilterOp> filter_;
  std::vector<std::unique_ptr<ops::LineFilterOp>> band_filters_;  // wavelet: one per level
};

}  // namespace riner::stripes
