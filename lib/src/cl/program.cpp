#include "cl/program.hpp"

#include <algorithm>
#include <atomic>

namespace riner::cl {

namespace {
std::atomic<long> g_live_buffers{0};
std::atomic<std::size_t> g_live_bytes{0};
std::atomic<std::size_t> g_peak_bytes{0};
}  // namespace

long live_buffer_count() { return g_live_buffers.load(); }
std::size_t peak_buffer_bytes() { return g_peak_bytes.load(); }
void note_buffer_created(std::size_t bytes) {
  ++g_live_buffers;
  const std::size_t live = g_live_bytes += bytes;
  std::size_t peak = g_peak_bytes.load();
  while (live > peak && !g_peak_bytes.compare_exchange_weak(peak, live)) {
  }
}
void note_buffer_released(std::size_t bytes) {
  --g_live_buffers;
  g_live_bytes -= bytes;
}

Kernel::Kernel(const Program& program, const std::string& name) : name_(name) {
  cl_int status = CL_SUCCESS;
  cl_kernel kernel = clCreateKernel(program.get(), name.c_str(), &status);
  if (status != CL_SUCCESS) {
    throw ClError(status, "clCreateKernel(" + name + " in " + program.name() + ")", RINER_HERE);
  }
  kernel_ = Handle<cl_kernel>(kernel);
}

void Kernel::set_raw(cl_uint index, std::size_t size, const void* value) {
  cl_int status = clSetKernelArg(kernel_.get(), index, size, value);
  if (status != CL_SUCCESS) {
    throw ClError(status, "clSetKernelArg(" + name_ + ", " + std::to_string(index) + ")",
                  RINER_HERE);
  }
}

std::size_t Kernel::max_work_group_size(cl_device_id device) const {
  std::size_t size = 0;
  RINER_CL_CALL(clGetKernelWorkGroupInfo, kernel_.get(), device, CL_KERNEL_WORK_GROUP_SIZE,
                sizeof(size), &size, nullptr);
  return size;
}

std::size_t Kernel::default_group(cl_device_id device) const {
  if (default_group_ == 0) {
    default_group_ = std::max<std::size_t>(1, std::min(kDefaultGroup, max_work_group_size(device)));
  }
  return default_group_;
}

}  // namespace riner::cl
