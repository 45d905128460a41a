#include "support/fixture.hpp"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <memory>
#include <mutex>
#include <random>
#include <string>

#include "riner/io.hpp"

namespace riner::test {

namespace {
std::mutex g_warnings_mutex;
std::vector<std::string> g_warnings;
}  // namespace

void record_warning(std::string_view message) {
  std::lock_guard<std::mutex> lock(g_warnings_mutex);
  g_warnings.emplace_back(message);
}

std::vector<std::string> take_warnings() {
  std::lock_guard<std::mutex> lock(g_warnings_mutex);
  std::vector<std::string> out;
  out.swap(g_warnings);
  return out;
}

std::uint64_t seed() {
  static const std::uint64_t value = [] {
    const char* env = std::getenv("RINER_TEST_SEED");
    return env != nullptr && *env != '\0' ? std::strtoull(env, nullptr, 10) : 20261122ull;
  }();
  return value;
}

Device& device() {
  // Never destroyed: some OpenCL runtimes (oclgrind) are torn down before static destructors
  // run, and releasing a context then crashes at exit.
  static Device* instance = [] {
    try {
      auto* d = new Device(Device::open("", /*profiling=*/true));
      std::printf("[riner tests] device: %s (%s, %s)\n", d->info().full_name().c_str(),
                  d->info().version.c_str(), d->info().opencl_c_version.c_str());
      return d;
    } catch (const std::exception& e) {
      std::fprintf(stderr, "[riner tests] no OpenCL device: %s (try `clinfo -l`)\n", e.what());
      std::exit(3);
    }
  }();
  return *instance;
}

TempDir::TempDir() {
  static std::mt19937_64 rng(std::random_device{}());
  path_ = std::filesystem::temp_directory_path() /
          ("riner_test_" + std::to_string(::getpid()) + "_" + std::to_string(rng()));
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

std::filesystem::path shared_data(const std::string& relative) {
  const std::filesystem::path path = std::filesystem::path(RINER_SHARED_DIR) / "data" / relative;
  return std::filesystem::exists(path) ? path : std::filesystem::path();
}

Array deeplesion_slice_mm(int index) {
  Array truth = read_array(shared_data("deeplesion/slice_" + std::to_string(index) + ".nii")).array;
  for (float& v : truth.data) v *= 0.1f;  // cm^-1 -> mm^-1
  return truth;
}

void write_bytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream file(path, std::ios::binary);
  file.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string read_bytes(const std::filesystem::path& path) {
  std::ifstream file(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
}

}  // namespace riner::test
