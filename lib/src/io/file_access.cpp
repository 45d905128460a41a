#include "io/file_access.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <system_error>
#include <vector>

#include "riner/array.hpp"
#include "riner/error.hpp"
#include "riner/io.hpp"

namespace riner {

namespace {

std::mutex& registry_mutex() {
  static std::mutex mutex;
  return mutex;
}

// Each input with the number of registrations that hold it: a scope's own end releases only
// its own (another thread's calls, or the process's, keep theirs).
std::map<std::filesystem::path, std::size_t>& registry() {
  static std::map<std::filesystem::path, std::size_t> inputs;
  return inputs;
}

// The paths registered on this thread while its innermost InputScope lives.
thread_local std::vector<std::filesystem::path>* scope_paths = nullptr;

std::filesystem::path canonical_or_absolute(const std::filesystem::path& path) {
  std::error_code error;
  std::filesystem::path result = std::filesystem::weakly_canonical(path, error);
  return error ? std::filesystem::absolute(path) : result;
}

}  // namespace

void register_input(const std::filesystem::path& path) {
  const std::filesystem::path input = canonical_or_absolute(path);
  std::lock_guard<std::mutex> lock(registry_mutex());
  ++registry()[input];
  if (scope_paths != nullptr) scope_paths->push_back(input);
}

InputScope::InputScope() : outer_(scope_paths) { scope_paths = &registered_; }

InputScope::~InputScope() {
  scope_paths = outer_;
  std::lock_guard<std::mutex> lock(registry_mutex());
  for (const std::filesystem::path& input : registered_) {
    const auto it = registry().find(input);
    if (it != registry().end() && --it->second == 0) registry().erase(it);
  }
}

void refuse_overwriting_input(const std::filesystem::path& path) {
  const std::filesystem::path target = canonical_or_absolute(path);
  std::error_code error;
  std::lock_guard<std::mutex> lock(registry_mutex());
  for (const auto& [input, holders] : registry()) {
    if (input == target || std::filesystem::equivalent(input, target, error)) {
      throw InputError(path.string() + ": refusing to overwrite an input file");
    }
  }
}

namespace io {

std::string prefix(const std::filesystem::path& path) { return path.string() + ": "; }

std::string lower_extension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

std::size_t element_count(const std::filesystem::path& path,
                          const std::vector<std::size_t>& shape) {
  try {
    return shape_size(shape);
  } catch (const InputError& e) {
    throw InputError(prefix(path) + e.what());
  }
}

std::uint64_t input_file_size(const std::filesystem::path& path) {
  std::error_code error;
  const auto status = std::filesystem::status(path, error);
  if (error || !std::filesystem::exists(status)) throw InputError(prefix(path) + "no such file");
  if (std::filesystem::is_directory(status)) throw InputError(prefix(path) + "is a directory");
  if (!std::filesystem::is_regular_file(status)) {
    throw InputError(prefix(path) + "is not a regular file");
  }
  const std::uint64_t size = std::filesystem::file_size(path, error);
  if (error) throw InputError(prefix(path) + "cannot read its size: " + error.message());
  return size;
}

std::string read_file_bytes(const std::filesystem::path& path) {
  const std::uint64_t size = input_file_size(path);
  std::ifstream file(path, std::ios::binary);
  if (!file) throw InputError(prefix(path) + "cannot open for reading");
  std::string bytes(size, '\0');
  if (!file.read(bytes.data(), static_cast<std::streamsize>(size))) {
    throw InputError(prefix(path) + "read failed");
  }
  register_input(path);
  return bytes;
}

void check_output_path(const std::filesystem::path& path) {
  refuse_overwriting_input(path);
  const std::filesystem::path target = canonical_or_absolute(path);
  const std::filesystem::path dir = target.parent_path();
  std::error_code error;
  if (!dir.empty() && !std::filesystem::is_directory(dir, error)) {
    throw InputError(prefix(path) + "output directory " + dir.string() + " does not exist");
  }
  if (std::filesystem::is_directory(target, error)) {
    throw InputError(prefix(path) + "is a directory");
  }
}

}  // namespace io
}  // namespace riner
