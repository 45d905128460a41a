// Which implementation runs a computation: the OpenCL kernels, or their CPU reference twins
// (Eigen, double accumulation) that the kernels are tested against.
#pragma once

#include <string>
#include <string_view>

namespace riner {

enum class Engine { kOpenCL, kReference };

// "opencl" or "reference"; InputError otherwise.
Engine parse_engine(std::string_view name);
const char* engine_name(Engine engine);

}  // namespace riner
