#include "ops/fbp.hpp"

#include <algorithm>

#include "riner/array.hpp"
#include "riner/error.hpp"

namespace riner::ops {

namespace {

std::vector<float> to_float(const std::vector<double>& v) { return {v.begin(), v.end()}; }

// Slices a work-item of fbp_backproject_parallel takes (kParallelSlices in kernels/fbp.cl).
constexpr std::size_t kParallelSlices = 4;
// A lanes work-item's tile of a slice (kLanes x kLaneRows in kernels/fbp.cl).
constexpr std::size_t kLanes = 16;
constexpr std::size_t kLaneRows = 4;

}  // namespace

FbpOp::FbpOp(cl::Context& context, const Geometry& geometry, const std::vector<double>& taps,
             const std::vector<double>& view_weights)
    : context_(context),
      geometry_(to_device(geometry)),
      divergent_(geometry.is_divergent()),
      views_(context, std::span<const cl_float2>(view_rotations(geometry))),
      line_filter_(context, geometry.n_u, taps),
      view_weights_(context, std::span<const float>(to_float(view_weights))),
      n_samples_(ray_count(geometry)),
      slice_voxels_(static_cast<cl_uint>(geometry.volume_shape[geometry.volume_shape.size() - 1] *
                                         geometry.volume_shape[geometry.volume_shape.size() - 2])),
      n_slices_(static_cast<cl_uint>(geometry.is_3d() ? geometry.volume_shape[0] : 1)),
      program_(context.program({"common", "ray_geometry", "fbp"})),
      backproject_parallel_(*program_, "fbp_backproject_parallel"),
      backproject_parallel_one_(*program_, "fbp_backproject_parallel_one"),
      backproject_divergent_(*program_, "fbp_backproject_divergent"),
      backproject_divergent_one_(*program_, "fbp_backproject_divergent_one"),
      pair_lines_(*program_, "fbp_pair_lines"),
      backproject_parallel_lanes_(*program_, "fbp_backproject_parallel_lanes"),
      backproject_divergent_lanes_(*program_, "fbp_backproject_divergent_lanes"),
      // Measured on PoCL (docs/history/RESULTS.md, "a CPU's backprojection"): 7-8x faster there.
      shape_(context.info().type == "CPU" ? Shape::kLanes : Shape::kPerVoxel) {
  if (taps.size() != 2 * geometry.n_u - 1 || view_weights.size() != geometry.n_views()) {
    throw Error("fbp: taps or view weights do not match the geometry");
  }
}

void FbpOp::filter(const cl::Buffer<float>& in, cl::Buffer<float>& out) {
  if (in.size() != n_samples_ || out.size() != n_samples_) throw Error("fbp_filter: size mismatch");
  const auto n_u = static_cast<std::size_t>(geometry_.n_u);
  line_filter_.run(in, out, LineLayout{n_samples_ / n_u, 0, n_u, 1});
}

void FbpOp::backproject(const cl::Buffer<float>& filtered, cl::Buffer<float>& volume,
                        std::size_t first_slice, std::size_t slice_step) {
  check_piece_size(0.0, static_cast<double>(volume.size()), "fbp");
  const std::size_t slices = volume.size() / slice_voxels_;
  if (filtered.size() != n_samples_ || volume.size() % slice_voxels_ != 0 || slices == 0 ||
      slice_step == 0 || first_slice + (slices - 1) * slice_step >= n_slices_) {
    throw Error("fbp_backproject: size mismatch");
  }
  if (shape_ == Shape::kLanes) {
    backproject_by_lanes(filtered, volume, first_slice, slice_step, slices);
    return;
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

void FbpOp::backproject_by_lanes(const cl::Buffer<float>& filtered, cl::Buffer<float>& volume,
                                 std::size_t first_slice, std::size_t slice_step,
                                 std::size_t slices) {
  const auto n_u = static_cast<std::size_t>(geometry_.n_u);
  const std::size_t rows = n_samples_ / n_u / static_cast<std::size_t>(geometry_.n_views);
  // The pairs of a chunk of views at a time: twice the filtered readings would be the largest
  // buffer of a volume's FDK.
  const std::size_t per_view = rows * (n_u + 3);
  const std::size_t chunk = std::clamp<std::size_t>(pairs_bytes_ / (per_view * sizeof(cl_float2)),
                                                    1, static_cast<std::size_t>(geometry_.n_views));
  cl::Buffer<cl_float2> pairs(context_, chunk * per_view);
  const std::size_t nx = static_cast<std::size_t>(geometry_.nx);
  const std::size_t ny = static_cast<std::size_t>(geometry_.ny);
  const std::size_t items =
      ((nx + kLanes - 1) / kLanes) * ((ny + kLaneRows - 1) / kLaneRows) * slices;
  cl::Kernel& kernel = divergent_ ? backproject_divergent_lanes_ : backproject_parallel_lanes_;
  for (std::size_t first = 0; first < static_cast<std::size_t>(geometry_.n_views); first += chunk) {
    const std::size_t views = std::min(chunk, static_cast<std::size_t>(geometry_.n_views) - first);
    const std::size_t pair_count = views * per_view;
    pair_lines_.set_args(static_cast<cl_uint>(pair_count), geometry_.n_u,
                         static_cast<cl_uint>(first * rows), filtered, pairs);
    context_.launch(pair_lines_, pair_count);
    kernel.set_args(static_cast<cl_uint>(items), static_cast<cl_uint>(first_slice),
                    static_cast<cl_uint>(slice_step), geometry_, views_, view_weights_,
                    static_cast<cl_int>(first), static_cast<cl_int>(views),
                    static_cast<cl_int>(first > 0), pairs, volume);
    context_.launch(kernel, items);
  }
}

}  // namespace riner::ops
