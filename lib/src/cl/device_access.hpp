// The context behind a public Device, for the library's own ops (and its tests and benchmarks):
// the OpenCL wrapper stays out of the public headers.
#pragma once

#include "cl/context.hpp"
#include "riner/device.hpp"

namespace riner {

namespace detail {

class DeviceAccess {
 public:
  static cl::Context& context(const Device& device) { return *device.context_; }
};

}  // namespace detail

namespace cl {

inline Context& context_of(const Device& device) { return detail::DeviceAccess::context(device); }

}  // namespace cl

}  // namespace riner
