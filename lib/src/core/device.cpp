#include "riner/device.hpp"

#include <algorithm>

#include "cl/check.hpp"
#include "cl/context.hpp"
#include "cl/device_list.hpp"
#include "cl/handle.hpp"

namespace riner {

std::string DeviceInfo::full_name() const { return platform + " / " + name; }

bool DeviceInfo::has_extension(std::string_view wanted) const {
  std::size_t at = 0;
  while (at < extensions.size()) {
    const std::size_t end = std::min(extensions.find(' ', at), extensions.size());
    if (std::string_view(extensions).substr(at, end - at) == wanted) return true;
    at = end + 1;
  }
  return false;
}

std::vector<DeviceInfo> list_devices() {
  std::vector<DeviceInfo> infos;
  for (cl::DeviceEntry& entry : cl::enumerate_devices()) infos.push_back(std::move(entry.info));
  return infos;
}

Device Device::open(std::string_view selector, bool profiling) {
  cl::DeviceEntry entry = cl::select_device(selector);
  auto context = std::make_shared<cl::Context>(entry.device, profiling);
  return Device(std::move(context));
}

Device Device::from_handles(cl_context context, cl_command_queue queue, bool profiling) {
  return Device(std::make_shared<cl::Context>(context, queue, profiling));
}

const DeviceInfo& Device::info() const { return context_->info(); }
bool Device::profiling() const { return context_->profiling(); }
void Device::finish() const { context_->finish(); }

Device Device::sibling() const {
  // The same context, a new queue: kernels of different contexts do not run at once on a GPU
  // (the driver time-slices contexts); those of one context's queues may.
  cl_int status = CL_SUCCESS;
  const cl_command_queue_properties props = context_->profiling() ? CL_QUEUE_PROFILING_ENABLE : 0;
  cl::Handle<cl_command_queue> queue(
      clCreateCommandQueue(context_->get(), context_->device(), props, &status));
  cl::check(status, "clCreateCommandQueue", RINER_HERE);
  return Device(std::make_shared<cl::Context>(context_->get(), queue.get(), context_->profiling()));
}

}  // namespace riner
