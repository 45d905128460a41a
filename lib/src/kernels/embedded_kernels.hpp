// Kernel sources compiled into the library (cmake/EmbedKernels.cmake) and their lookup.
#pragma once

#include <span>
#include <string>
#include <string_view>

namespace riner::kernels {

struct EmbeddedKernel {
  std::string_view name;  // file stem: "common" for kernels/common.cl
  std::string_view source;
};

std::span<const EmbeddedKernel> embedded_kernels();

// The source of kernels/<name>.cl: read from $RINER_KERNEL_DIR when that is set and holds the
// file (for kernel development without rebuilding), else the embedded copy. Throws Error for
// an unknown name.
std::string kernel_source(std::string_view name);

}  // namespace riner::kernels
