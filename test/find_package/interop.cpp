// A consumer that owns its OpenCL objects through the Khronos C++ bindings at OpenCL 3.0 and
// hands them to riner (Device::from_handles): riner's headers must leave the caller's
// CL_TARGET_OPENCL_VERSION alone (they pinned it at 1.2, and <CL/opencl.hpp> failed with 244
// errors).
#include <cstdio>

#include <CL/opencl.hpp>

#include "riner/device.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/geometry.hpp"
#include "riner/phantom.hpp"
#include "riner/scan.hpp"
#include "riner/simulate.hpp"

int main() {
  try {
    cl::Context context(CL_DEVICE_TYPE_ALL);
    cl::CommandQueue queue(context);
    riner::Device device = riner::Device::from_handles(context(), queue());
    const riner::Geometry g = riner::Geometry::from_json(R"({"type": "parallel2d",
        "detector": {"count": 48, "pitch_mm": 1.0},
        "angles": {"count": 60, "start_rad": 0.0, "range_rad": 3.141592653589793},
        "volume": {"shape": [32, 32], "voxel_mm": 1.0}})");
    const riner::Scan scan{riner::exact_projections(riner::shepp_logan(g), g), g, 0};
    riner::FbpOptions options;
    options.device = device;
    const riner::Array image = riner::fbp(scan, options);
    std::printf("interop: FBP of %zu pixels on the caller's queue\n", image.size());
    return image.size() == 32 * 32 ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "interop: %s\n", e.what());
    return 1;
  }
}
