#include "riner/engine.hpp"

#include "riner/error.hpp"

namespace riner {

Engine parse_engine(std::string_view name) {
  if (name == "opencl") return Engine::kOpenCL;
  if (name == "reference") return Engine::kReference;
  throw InputError("engine must be opencl or reference (got \"" + std::string(name) + "\")");
}

const char* engine_name(Engine engine) {
  return engine == Engine::kOpenCL ? "opencl" : "reference";
}

}  // namespace riner
