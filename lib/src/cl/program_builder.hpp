// Builds programs from embedded kernel sources, through an on-disk binary cache.
//
// Cache entries live in $RINER_CACHE_DIR, else $XDG_CACHE_HOME/riner, else ~/.cache/riner
// (RINER_CACHE_DIR=off disables the cache). An entry is keyed by the sources' hash, the build
// options, the device name and the driver and platform versions; its file stores the whole key
// and a checksum of the binary, so a collision, a truncated write or a corrupt file is noticed,
// the entry discarded and the program built from source. Entries are written to a unique
// temporary file and renamed into place, so concurrent processes never see a partial entry.
//
// A driver that keeps its own cache of compiled kernels (PoCL: ~/.cache/pocl) gets no entries:
// asking PoCL for a program's binary compiles every kernel in it once more, which doubled a
// first run (docs/history/RESULTS.md, "the program cache on PoCL") and saved 0.2 s on the next.
#pragma once

#include <CL/cl.h>

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cl/handle.hpp"

namespace riner::cl {

std::optional<std::filesystem::path> binary_cache_dir();

struct BuiltProgram {
  Handle<cl_program> program;
  bool from_disk = false;
};

// Whether riner's cache serves a device of this platform (false for PoCL, see above).
bool disk_cache_serves(const std::string& platform);
// The tests' way to exercise the cache on PoCL: every platform served while on.
void serve_every_platform_for_tests(bool on);

// sources are kernel file stems; the option string is used verbatim after "-cl-std=CL1.2" and
// before $RINER_CL_BUILD_OPTIONS. use_disk_cache false: built from source, nothing stored.
BuiltProgram build_program(cl_context context, cl_device_id device,
                           const std::vector<std::string>& sources, const std::string& options,
                           const std::string& device_key, bool use_disk_cache = true);

}  // namespace riner::cl
