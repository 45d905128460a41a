#include "ops/project.hpp"

#include "riner/array.hpp"
#include "riner/error.hpp"

namespace riner::ops {

ProjectOp::ProjectOp(cl::Context& context, const Geometry& geometry)
    : context_(context),
      geometry_(to_device(geometry)),
      views_(context, std::span<const cl_float2>(view_rotations(geometry))),
      n_rays_(ray_count(geometry)),
      volume_size_(checked_volume_size(geometry)),
      program_(context.program({"common", "ray_geometry", "joseph", "project"})),
      kernel_(*program_, "project_forward"),
      lanes_kernel_(*program_, "project_forward_lanes"),
      transpose_kernel_(*program_, "project_transpose_xy"),
      shape_(context.info().type == "CPU" ? Shape::kLanes : Shape::kPerRay) {}

void ProjectOp::forward(const cl::Buffer<float>& volume, cl::Buffer<float>& out) {
  if (volume.size() != volume_size_ || out.size() != n_rays_) {
    throw Error("project_forward: buffer sizes do not match the geometry");
  }
  if (shape_ == Shape::kLanes) {
    // PROJECT_LANES in kernels/project.cl.
    constexpr cl_uint kLanes = 16;
    const auto n_u = static_cast<cl_uint>(geometry_.n_u);
    const cl_uint items = n_rays_ / n_u * ((n_u + kLanes - 1) / kLanes);
    cl::Buffer<float> volume_t(context_, volume_size_);
    transpose_kernel_.set_args(static_cast<cl_uint>(volume_size_), geometry_, volume, volume_t);
    context_.launch(transpose_kernel_, volume_size_);
    lanes_kernel_.set_args(items, geometry_, views_, volume, volume_t, out);
    context_.launch(lanes_kernel_, items);
    return;
  }
  kernel_.set_args(n_rays_, geometry_, views_, volume, out);
  context_.launch(kernel_, n_rays_);
}

}  // namespace riner::ops
