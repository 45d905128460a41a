#include "ops/stripe_sorting.hpp"

#include <algorithm>

#include "ops/stripe_steps.hpp"
#include "riner/error.hpp"

namespace riner::ops {

namespace {

constexpr std::size_t kMostWindow = 255;  // kernels/stripe_sorting.cl
constexpr std::size_t kSortGroup = 256;

std::size_t power_of_two_at_least(std::size_t n) {
  std::size_t p = 1;
  while (p < n) p *= 2;
  return p;
}

std::size_t local_bytes(std::size_t views) {
  return power_of_two_at_least(views) * (sizeof(float) + sizeof(cl_uint));
}

bool on_cpu(const cl::Context& context) { return context.info().type == "CPU"; }

// Whether the bitonic sort's column of `views` fits the device's local memory.
bool bitonic_fits(const cl::Context& context, std::size_t views) {
  return local_bytes(views) + 1024 <= context.info().local_mem_bytes;
}

void require_bitonic_fits(const cl::Context& context, std::size_t views) {
  if (!bitonic_fits(context, views)) {
    throw Error("stripe sorting: a column of " + std::to_string(views) +
                " views does not fit the device's local memory");
  }
}

}  // namespace

bool StripeSortingOp::supported(const cl::Context& context, std::size_t views, std::size_t size) {
  return size % 2 == 1 && size <= kMostWindow && views >= 2 &&
         (on_cpu(context) || bitonic_fits(context, views));
}

StripeSortingOp::StripeSortingOp(cl::Context& context, std::size_t views, std::size_t columns)
    : context_(context),
      views_(static_cast<cl_uint>(views)),
      columns_(static_cast<cl_uint>(columns)),
      padded_(static_cast<cl_uint>(power_of_two_at_least(views))),
      program_(context.program(stripe_program_sources())),
      sort_(*program_, "sort_columns"),
      median_(*program_, "median_across_columns"),
      smooth_(*program_, "smooth_along_ranks"),
      unsort_(*program_, "unsort_columns"),
      sort_merge_(*program_, "sort_columns_merge"),
      median_sliding_(*program_, "median_across_columns_sliding"),
      // Measured on PoCL (docs/history/RESULTS.md, "the sorting step on a CPU").
      shape_(on_cpu(context) ? Shape::kSerial : Shape::kBitonic),
      sorted_(context, views * columns),
      filtered_(context, views * columns),
      order_(context, views * columns) {
  if (views < 2) throw Error("stripe sorting: a column needs at least 2 views");
  if (shape_ == Shape::kBitonic) require_bitonic_fits(context, views);
}

void StripeSortingOp::use_shape(Shape shape) {
  if (shape == Shape::kBitonic) require_bitonic_fits(context_, views_);
  shape_ = shape;
}

void StripeSortingOp::apply(const cl::Buffer<float>& in, cl::Buffer<float>& out, std::size_t size,
                            std::size_t rank_window) {
  sort(in);
  median(size);
  if (rank_window <= 1) {
    unsort(out);
    return;
  }
  if (rank_window % 2 == 0) throw Error("stripe sorting: an even window along the ranks");
  if (smoothed_.size() != sorted_.size()) smoothed_ = cl::Buffer<float>(context_, sorted_.size());
  smooth_.set_args(views_, columns_, static_cast<cl_uint>(rank_window), sorted_, filtered_,
                   smoothed_);
  context_.launch(smooth_, std::size_t{columns_});
  unsort_from(smoothed_, out);
}

void StripeSortingOp::sort(const cl::Buffer<float>& in) {
  if (in.size() != sorted_.size()) throw Error("stripe sorting: size mismatch");
  if (shape_ == Shape::kSerial) {
    if (keys_.size() != sorted_.size()) {
      keys_ = cl::Buffer<float>(context_, sorted_.size());
      views_a_ = cl::Buffer<cl_uint>(context_, sorted_.size());
      views_b_ = cl::Buffer<cl_uint>(context_, sorted_.size());
    }
    // filtered_ is the second scratch of keys: median() overwrites it before anyone reads it.
    sort_merge_.set_args(views_, columns_, in, sorted_, order_, keys_, views_a_, filtered_,
                         views_b_);
    context_.launch(sort_merge_, std::size_t{columns_});
    return;
  }
  const std::size_t group = std::min({kSortGroup, static_cast<std::size_t>(padded_) / 2 + 1,
                                      sort_.max_work_group_size(context_.device())});
  sort_.set_args(views_, columns_, padded_, in, sorted_, order_,
                 cl::LocalMemory{padded_ * sizeof(float)}, cl::LocalMemory{padded_ * sizeof(cl_uint)});
  context_.launch(sort_, cl::Range(std::size_t{columns_} * group), cl::Range(group));
}

void StripeSortingOp::median(std::size_t size) {
  if (size % 2 == 0 || size > kMostWindow) throw Error("stripe sorting: an even or too wide window");
  if (shape_ == Shape::kSerial) {
    median_sliding_.set_args(views_, columns_, static_cast<cl_uint>(size), sorted_, filtered_);
    context_.launch(median_sliding_, std::size_t{views_});
    return;
  }
  median_.set_args(views_, columns_, static_cast<cl_uint>(size), sorted_, filtered_);
  context_.launch(median_, sorted_.size());
}

void StripeSortingOp::unsort(cl::Buffer<float>& out) { unsort_from(filtered_, out); }

void StripeSortingOp::unsort_from(const cl::Buffer<float>& ranked, cl::Buffer<float>& out) {
  if (out.size() != sorted_.size()) throw Error("stripe sorting: size mismatch");
  unsort_.set_args(views_, columns_, ranked, order_, out);
  context_.launch(unsort_, sorted_.size());
}

}  // namespace riner::ops
