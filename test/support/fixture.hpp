// What every test executable shares: the seed, one OpenCL device per process, scratch
// directories, and warnings captured instead of printed.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "riner/array.hpp"
#include "riner/device.hpp"

namespace riner::test {

// Fixed default, printed at start-up; RINER_TEST_SEED overrides it.
std::uint64_t seed();

// The process-wide test device (profiling queue). Fails the test run when there is none:
// PoCL is a dependency, so a missing device is a broken setup, not a skip.
Device& device();

// Warnings the library sent since the last call (the test main captures them).
std::vector<std::string> take_warnings();

// A fresh directory under the system temp dir, removed with the object.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

// Path into ../shared/data, or empty when the shared data is not beside the checkout.
std::filesystem::path shared_data(const std::string& relative);
// Shared DeepLesion slice `index` (deeplesion/slice_N.nii, cm^-1) in mm^-1, as METHOD.md §4
// simulates it; the shared data must be there.
Array deeplesion_slice_mm(int index);

void write_bytes(const std::filesystem::path& path, const std::string& bytes);
std::string read_bytes(const std::filesystem::path& path);

}  // namespace riner::test
