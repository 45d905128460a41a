// Host side of kernels/project.cl: the forward projector (Joseph's method).
#pragma once

#include <memory>

#include "cl/buffer.hpp"
#include "cl/program.hpp"
#include "ops/device_geometry.hpp"

namespace riner::ops {

class ProjectOp {
 public:
  ProjectOp(cl::Context& context, const Geometry& geometry);

  // out[view][row][element] = line integral of volume[nz][ny][nx] along that ray.
  void forward(const cl::Buffer<float>& volume, cl::Buffer<float>& out);

  // How forward() lays its work out (kernels/project.cl): one ray per work-item (a GPU's
  // shape), or 16 neighbouring rays of a detector row in vectors (a CPU's, the default on a CPU
  // device; it holds a copy of the volume with x and y swapped while it runs). The same sums
  // either way; the tests run both on one device.
  enum class Shape { kPerRay, kLanes };
  void use_shape(Shape shape) { shape_ = shape; }

  std::size_t volume_size() const { return volume_size_; }
  std::size_t measurement_size() const { return n_rays_; }

 private:
  cl::Context& context_;
  DeviceGeometry geometry_;
  cl::Buffer<cl_float2> views_;
  cl_uint n_rays_;
  std::size_t volume_size_;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel kernel_;
  cl::Kernel lanes_kernel_;
  cl::Kernel transpose_kernel_;
  Shape shape_;
};

}  // namespace riner::ops
