#include "ops/fbp.hpp"

#include "riner/array.hpp"
#include "riner/error.hpp"

namespace riner::ops {

namespace {
std::vector<float> to_float(const std::vector<double>& v) { return {v.begin(), v.end()}; }
}  // namespace

FbpOp::FbpOp(cl::Context& context, const Geometry& geometry, const std::vector<double>& taps,
             const std::vector<double>& view_weights)
    : context_(context),
      geometry_(to_device(geometry)),
      views_(context, std::span<const cl_float2>(view_rotations(geometry))),
      taps_(context, std::span<const float>(to_float(taps))),
      view_weights_(context, std::span<const float>(to_float(view_weights))),
      n_samples_(ray_count(geometry)),
      slice_voxels_(static_cast<cl_uint>(geometry.volume_shape[geometry.volume_shape.size() - 1] *
                                         geometry.volume_shape[geometry.volume_shape.size() - 2])),
      n_slices_(static_cast<cl_uint>(geometry.is_3d() ? geometry.volume_shape[0] : 1)),
      program_(context.program({"common", "ray_geometry", "fbp"})),
      filter_(*program_, "fbp_filter"),
      backproject_(*program_, "fbp_backproject") {
  if (taps.size() != 2 * geometry.n_u - 1 || view_weights.size() != geometry.n_views()) {
    throw Error("fbp: taps or view weights do not match the geometry");
  }
}

void FbpOp::filter(const cl::Buffer<float>& in, cl::Buffer<float>& out) {
  if (in.size() != n_samples_ || out.size() != n_samples_) throw Error("fbp_filter: size mismatch");
  filter_.set_args(n_samples_, static_cast<cl_int>(geometry_.n_u), taps_, in, out);
  context_.launch(filter_, n_samples_);
}

void FbpOp::backproject(const cl::Buffer<float>& filtered, cl::Buffer<float>& volume,
                        std::size_t first_slice, std::size_t slice_step) {
  const std::size_t slices = volume.size() / slice_voxels_;
  if (filtered.size() != n_samples_ || volume.size() % slice_voxels_ != 0 || slices == 0 ||
      slice_step == 0 || first_slice + (slices - 1) * slice_step >= n_slices_) {
    throw Error("fbp_backproject: size mismatch");
  }
  const auto n = static_cast<cl_uint>(volume.size());
  backproject_.set_args(n, static_cast<cl_uint>(first_slice), static_cast<cl_uint>(slice_step),
                        geometry_, views_, view_weights_, filtered, volume);
  context_.launch(backproject_, volume.size());
}

}  // namespace riner::ops
