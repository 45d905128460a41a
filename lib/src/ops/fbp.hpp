// Host side of kernels/fbp.cl: ramp filtering by FFT (by direct convolution where a padded
// line does not fit the device's local memory), and the pixel-driven weighted backprojection of
// FBP/FDK.
#pragma once

#include <memory>
#include <vector>

#include "cl/buffer.hpp"
#include "cl/program.hpp"
#include "ops/device_geometry.hpp"

namespace riner::ops {

class FbpOp {
 public:
  FbpOp(cl::Context& context, const Geometry& geometry, const std::vector<double>& taps,
        const std::vector<double>& view_weights);

  // out = in convolved with the taps along every detector row.
  void filter(const cl::Buffer<float>& in, cl::Buffer<float>& out);
  // Whether filter() goes by FFT; false: by direct convolution (also when `direct` is asked).
  bool filters_by_fft() const { return fft_size_ > 0; }
  void use_direct_filter() { fft_size_ = 0; }
  // volume = weighted backprojection of the filtered measurement onto the axial slices
  // first_slice, first_slice + slice_step, ... (as many as volume holds; 2D: 0, 1).
  void backproject(const cl::Buffer<float>& filtered, cl::Buffer<float>& volume,
                   std::size_t first_slice = 0, std::size_t slice_step = 1);

 private:
  cl::Context& context_;
  DeviceGeometry geometry_;
  bool divergent_;
  cl::Buffer<cl_float2> views_;
  cl::Buffer<float> taps_;
  cl_uint fft_size_ = 0;  // the padded line's length; 0: direct convolution
  cl::Buffer<cl_float2> spectrum_;  // the taps', bit-reversed, over fft_size_
  cl::Buffer<cl_float2> twiddles_;
  cl::Buffer<float> view_weights_;
  cl_uint n_samples_;
  cl_uint slice_voxels_;  // nx * ny
  cl_uint n_slices_;
  std::shared_ptr<const cl::Program> program_;
  cl::Kernel filter_;
  cl::Kernel filter_fft_;
  cl::Kernel backproject_parallel_;
  cl::Kernel backproject_parallel_one_;
  cl::Kernel backproject_divergent_;
  cl::Kernel backproject_divergent_one_;
};

}  // namespace riner::ops
