// OpenCL devices: discovery, capabilities and selection.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

// OpenCL's handle types (cl_context and cl_command_queue point to these), named without
// <CL/cl.h>, whose CL_TARGET_OPENCL_VERSION would then be riner's rather than the caller's.
struct _cl_context;
struct _cl_command_queue;

namespace riner {

namespace cl {
class Context;
}
namespace detail {
class DeviceAccess;  // the library's own way to a Device's context (lib/src/cl/device_access.hpp)
}

// What later kernels need to know about a device.
struct DeviceInfo {
  int index = 0;  // position in list_devices()
  std::string platform;
  std::string platform_version;
  std::string name;
  std::string vendor;
  std::string type;  // "GPU", "CPU", "accelerator", "other"
  std::string version;
  std::string driver_version;
  std::string opencl_c_version;
  std::uint32_t compute_units = 0;
  std::uint32_t max_clock_mhz = 0;
  std::size_t max_work_group_size = 0;
  std::uint64_t local_mem_bytes = 0;
  bool local_mem_is_global = false;  // CPUs emulate local memory in global memory
  std::uint64_t global_mem_bytes = 0;
  std::uint64_t max_alloc_bytes = 0;
  bool fp64 = false;
  std::uint32_t preferred_vector_width_float = 0;
  std::uint32_t native_vector_width_float = 0;
  std::uint32_t preferred_vector_width_int = 0;
  std::uint32_t native_vector_width_int = 0;
  std::string extensions;               // CL_DEVICE_EXTENSIONS, space-separated
  bool fp32_global_atomic_add = false;  // cl_ext_float_atomics reports global float add

  bool has_extension(std::string_view name) const;

  // "Portable Computing Language / pthread-skylake-avx512-..."
  std::string full_name() const;
};

// Every device of every platform; empty when no OpenCL platform is installed.
std::vector<DeviceInfo> list_devices();

// An OpenCL context and in-order queue on one device: what every riner computation runs on.
// Cheap to copy (shared ownership).
class Device {
 public:
  // selector: "" (then $RINER_DEVICE, then the first GPU, then the first device), a device
  // index from list_devices(), or a case-insensitive substring of "platform / device".
  // Throws Error when nothing matches or no device exists.
  static Device open(std::string_view selector = "", bool profiling = false);

  // Wraps a context and queue the caller already has (interop); riner retains them. Error when
  // the queue is out of order (every step relies on the order) or of another context.
  static Device from_handles(_cl_context* context, _cl_command_queue* queue, bool profiling = false);

  const DeviceInfo& info() const;
  bool profiling() const;

  // Finishes all queued work.
  void finish() const;

  // A new in-order queue in the same context: for a second training at once
  // (riner/concurrent_trainings.hpp). Its work is ordered only against its own queue.
  Device sibling() const;

 private:
  friend class detail::DeviceAccess;
  explicit Device(std::shared_ptr<cl::Context> context) : context_(std::move(context)) {}
  std::shared_ptr<cl::Context> context_;
};

}  // namespace riner
