// Host side of kernels/backproject.cl: the exact adjoint of the projector.
#pragma once

#include <memory>

#include "cl/buffer.hpp"
#include "cl/program.hpp"
#include "ops/device_geometry.hpp"
#include "ops/vector_ops.hpp"

namespace riner::ops {

class BackprojectOp {
 public:
  BackprojectOp(cl::Context& context, const Geometry& geometry);

  // volume = A^T values (volume is overwritten). Float atomics: not bit-deterministic.
  void adjoint(const cl::Buffer<float>& values, cl::Buffer<float>& volume);

 private:
  cl::Context& context_;
  DeviceGeometry geometry_;
  cl::Buffer<cl_float2> views_;
  cl_uint n_rays_;
  std::size_t volume_size_;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel kernel_;
  VectorOps vector_ops_;
};

}  // namespace riner::ops
