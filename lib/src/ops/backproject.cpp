#include "ops/backproject.hpp"

#include "riner/array.hpp"
#include "riner/error.hpp"

namespace riner::ops {

BackprojectOp::BackprojectOp(cl::Context& context, const Geometry& geometry)
    : context_(context),
      geometry_(to_device(geometry)),
      views_(context, std::span<const cl_float2>(view_rotations(geometry))),
      n_rays_(ray_count(geometry)),
      volume_size_(checked_volume_size(geometry)),
      program_(context.program({"common", "ray_geometry", "joseph", "backproject"})),
      kernel_(*program_, "backproject_adjoint"),
      vector_ops_(context) {}

void BackprojectOp::adjoint(const cl::Buffer<float>& values, cl::Buffer<float>& volume) {
  if (values.size() != n_rays_ || volume.size() != volume_size_) {
    throw Error("backproject_adjoint: buffer sizes do not match the geometry");
  }
  vector_ops_.fill(volume, 0.0f);
  kernel_.set_args(n_rays_, geometry_, views_, values, volume);
  context_.launch(kernel_, n_rays_);
}

}  // namespace riner::ops
