#include <cstdlib>
#include <fstream>
#include <iterator>

#include "kernels/embedded_kernels.hpp"
#include "riner/error.hpp"

namespace riner::kernels {

std::string kernel_source(std::string_view name) {
  if (const char* dir = std::getenv("RINER_KERNEL_DIR"); dir != nullptr && *dir != '\0') {
    std::ifstream file(std::string(dir) + "/" + std::string(name) + ".cl", std::ios::binary);
    if (file) {
      return std::string((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    }
  }
  for (const EmbeddedKernel& kernel : embedded_kernels()) {
    if (kernel.name == name) return std::string(kernel.source);
  }
  throw Error("no kernel source named '" + std::string(name) + "' is embedded in riner");
}

}  // namespace riner::kernels
