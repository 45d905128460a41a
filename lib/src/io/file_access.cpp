#include "io/file_access.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>
#include <mutex>
#include <set>
#include <system_error>

#include "riner/array.hpp"
#include "riner/error.hpp"
#include "riner/io.hpp"

namespace riner {

namespace {

std::mutex& registry_mutex() {
  static std::mutex mutex;
  return mutex;
}

std::set<std::filesystem::path>& registry() {
  static std::set<std::filesystem::path> inputs;
  return inputs;
}

std::filesystem::path canonical_or_absolute(const std::filesystem::path& path) {
  std::error_code error;
  std::filesystem::path result = std::filesystem::weakly_canonical(path, error);
  return error ? std::filesystem::absolute(path) : result;
}

}  // namespace

void register_input(const std::filesystem::path& path) {
  std::lock_guard<std::mutex> lock(registry_mutex());
  registry().insert(canonical_or_absolute(path));
}

InputScope::InputScope() {
  std::lock_guard<std::mutex> lock(registry_mutex());
  before_.assign(registry().begin(), registry().end());
}

InputScope::~InputScope() {
  std::lock_guard<std::mutex> lock(registry_mutex());
  registry() = std::set<std::filesystem::path>(before_.begin(), before_.end());
}

void refuse_overwriting_input(const std::filesystem::path& path) {
  const std::filesystem::path target = canonical_or_absolute(path);
  std::error_code error;
  const bool folder = std::filesystem::is_directory(target, error);
  std::lock_guard<std::mutex> lock(registry_mutex());
  for (const std::filesystem::path& input : registry()) {
    if (input == target || std::filesystem::equivalent(input, target, error)) {
      throw InputError(path.string() + ": refusing to overwrite an input file");
    }
    // A folder that holds an input TIFF (a folder of TIFFs read as a stack) takes no slices:
    // they would join the stack.
    if (folder && input.parent_path() == target &&
        (io::lower_extension(input) == ".tif" || io::lower_extension(input) == ".tiff")) {
      throw InputError(path.string() + ": refusing to write into a folder that holds an input (" +
                       input.filename().string() + ")");
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
