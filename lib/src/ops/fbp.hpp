// Host side of FBP/FDK on the device: ramp filtering along each detector row
// (ops/line_filter.hpp), and the pixel-driven weighted backprojection of kernels/fbp.cl.
#pragma once

#include <memory>
#include <vector>

#include "cl/buffer.hpp"
#include "cl/program.hpp"
#include "ops/line_filter.hpp"
#include "ops/device_geometry.hpp"

namespace riner::ops {

class FbpOp {
 public:
  FbpOp(cl::Context& context, const Geometry& geometry, const std::vector<double>& taps,
        const std::vector<double>& view_weights);

  // out = in convolved with the taps along every detector row.
  void filter(const cl::Buffer<float>& in, cl::Buffer<float>& out);
  // Whether filter() goes by FFT in local memory; false: by FFT in global memory (a line that
  // does not fit) or, when the tests ask for it, by direct convolution.
  bool filters_by_fft() const { return line_filter_.by_fft(); }
  void use_filter_path(LineFilterOp::Path path, std::size_t groups = 0) {
    line_filter_.use(path, groups);
  }
  // How backproject() lays its work out (kernels/fbp.cl): one voxel per work-item (a GPU's
  // shape), or vectors of voxels that read the detector's values as pairs (a CPU's, the
  // default on a CPU device; the pairs of a chunk of views, at most 64 MiB, while it runs).
  enum class Shape { kPerVoxel, kLanes };
  // The tests' way to run both shapes on one device; `pairs_bytes` > 0 bounds the CPU's shape's
  // pairs to a chunk of views that size (default 64 MiB: every view of a slice at once).
  void use_shape(Shape shape, std::size_t pairs_bytes = 0) {
    shape_ = shape;
    if (pairs_bytes > 0) pairs_bytes_ = pairs_bytes;
  }
  // volume = weighted backprojection of the filtered measurement onto the axial slices
  // first_slice, first_slice + slice_step, ... (as many as volume holds; 2D: 0, 1).
  void backproject(const cl::Buffer<float>& filtered, cl::Buffer<float>& volume,
                   std::size_t first_slice = 0, std::size_t slice_step = 1);

 private:
  void backproject_by_lanes(const cl::Buffer<float>& filtered, cl::Buffer<float>& volume,
                            std::size_t first_slice, std::size_t slice_step, std::size_t slices);

  cl::Context& context_;
  DeviceGeometry geometry_;
  bool divergent_;
  cl::Buffer<cl_float2> views_;
  LineFilterOp line_filter_;
  cl::Buffer<float> view_weights_;
  cl_uint n_samples_;
  cl_uint slice_voxels_;  // nx * ny
  cl_uint n_slices_;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel backproject_parallel_;
  cl::Kernel backproject_parallel_one_;
  cl::Kernel backproject_divergent_;
  cl::Kernel backproject_divergent_one_;
  cl::Kernel pair_lines_;
  cl::Kernel backproject_parallel_lanes_;
  cl::Kernel backproject_divergent_lanes_;
  Shape shape_;
  std::size_t pairs_bytes_ = std::size_t{64} << 20;
};

}  // namespace riner::ops
