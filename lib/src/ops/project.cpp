#include "ops/project.hpp"

#include "riner/array.hpp"
#include "riner/error.hpp"

namespace riner::ops {

ProjectOp::ProjectOp(cl::Context& context, const Geometry& geometry)
    : context_(context),
      geometry_(to_device(geometry)),
      views_(context, std::span<const cl_float2>(view_rotations(geometry))),
      n_rays_(ray_count(geometry)),
      volume_size_(shape_size(geometry.volume_shape)),
      program_(context.program({"common", "ray_geometry", "joseph", "project"})),
      kernel_(*program_, "project_forward") {}

void ProjectOp::forward(const cl::Buffer<float>& volume, cl::Buffer<float>& out) {
  if (volume.size() != volume_size_ || out.size() != n_rays_) {
    throw Error("project_forward: buffer sizes do not match the geometry");
  }
  kernel_.set_args(n_rays_, geometry_, views_, volume, out);
  context_.launch(kernel_, n_rays_);
}

}  // namespace riner::ops
