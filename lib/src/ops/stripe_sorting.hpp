// Host side of kernels/stripe_sorting.cl: Vo's sorting step (each column sorted over the views,
// a median across columns at each rank, unsorted) on one sinogram at a time.
#pragma once

#include <memory>

#include "cl/buffer.hpp"
#include "cl/context.hpp"
#include "cl/program.hpp"

namespace riner::ops {

class StripeSortingOp {
 public:
  // Error when there are fewer than 2 views, or (a GPU's shape) a column of `views` readings
  // does not fit the device's local memory; supported() also says whether a window `size` is
  // odd and within the kernels' widest.
  StripeSortingOp(cl::Context& context, std::size_t views, std::size_t columns);
  static bool supported(const cl::Context& context, std::size_t views, std::size_t size);

  // out [views][columns]: in with every column's sorted readings replaced by their median
  // across `size` neighbouring columns at the same rank, that correction averaged over the
  // `rank_window` ranks around each (1: as it is; in and out may be one buffer).
  void apply(const cl::Buffer<float>& in, cl::Buffer<float>& out, std::size_t size,
             std::size_t rank_window);

  // The three steps apart, for large-stripe removal: sort() ranks in's columns (sorted(),
  // and the views they came from); median() fills filtered() from sorted(); unsort() puts
  // filtered() back in the views of the last sort().
  void sort(const cl::Buffer<float>& in);
  void median(std::size_t size);
  void unsort(cl::Buffer<float>& out);
  const cl::Buffer<float>& sorted() const { return sorted_; }
  const cl::Buffer<float>& filtered() const { return filtered_; }

  // How sort() and median() lay their work out (kernels/stripe_sorting.cl): a bitonic sort in
  // local memory per column and a quickselect per element (a GPU's shape), or a merge sort per
  // column and a sliding window per rank (a CPU's, the default on a CPU device). The same
  // results to the bit; the tests run both on one device.
  enum class Shape { kBitonic, kSerial };
  void use_shape(Shape shape);
  Shape shape() const { return shape_; }

 private:
  // Values at each rank of the last sort() put back in the views they came from.
  void unsort_from(const cl::Buffer<float>& ranked, cl::Buffer<float>& out);

  cl::Context& context_;
  cl_uint views_, columns_, padded_;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel sort_, median_, smooth_, unsort_, sort_merge_, median_sliding_;
  Shape shape_;
  cl::Buffer<float> sorted_, filtered_;
  cl::Buffer<float> smoothed_;  // apply()'s correction averaged along the ranks
  cl::Buffer<cl_uint> order_;
  cl::Buffer<float> keys_;  // the merge sort's scratch (kSerial only), with filtered_
  cl::Buffer<cl_uint> views_a_, views_b_;
};

}  // namespace riner::ops
