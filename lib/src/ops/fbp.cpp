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
      n_voxels_(static_cast<cl_uint>(shape_size(geometry.volume_shape))),
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

void FbpOp::backproject(const cl::Buffer<float>& filtered, cl::Buffer<float>& volume) {
  if (filtered.size() != n_samples_ || volume.size() != n_voxels_) {
    throw Error("fbp_backproject: size mismatch");
  }
  backproject_.set_args(n_voxels_, geometry_, views_, view_weights_, filtered, volume);
  context_.launch(backproject_, n_voxels_);
}

}  // namespace riner::ops
