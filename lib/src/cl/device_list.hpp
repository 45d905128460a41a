// Enumerating OpenCL platforms and devices, and choosing one from a selector string.
#pragma once

#include <CL/cl.h>

#include <string_view>
#include <vector>

#include "riner/device.hpp"

namespace riner::cl {

struct DeviceEntry {
  cl_platform_id platform = nullptr;
  cl_device_id device = nullptr;
  DeviceInfo info;
};

std::vector<DeviceEntry> enumerate_devices();

DeviceInfo query_device_info(cl_device_id device);

// See Device::open for the selector grammar. Throws Error naming the selector when nothing
// matches, and Error with a hint to `clinfo -l` when there is no device at all.
DeviceEntry select_device(std::string_view selector);

}  // namespace riner::cl
