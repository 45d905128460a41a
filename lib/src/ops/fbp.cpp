#include "ops/fbp.hpp"

#include "riner/array.hpp"
#include "riner/error.hpp"

namespace riner::ops {

namespace {

std::vector<float> to_float(const std::vector<double>& v) { return {v.begin(), v.end()}; }

// Slices a work-item of fbp_backproject_parallel takes (kParallelSlices in kernels/fbp.cl).
constexpr std::size_t kParallelSlices = 4;

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
      backproject_divergent_one_(*program_, "fbp_backproject_divergent_one") {
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
