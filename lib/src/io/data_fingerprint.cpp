#include "io/data_fingerprint.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <vector>

#include "io/file_access.hpp"
#include "io/stack.hpp"
#include "riner/error.hpp"
#include "riner/tomo_file.hpp"
#include "util/hash.hpp"

namespace riner::io {

namespace {

constexpr std::uint64_t kBlocks = 16;
constexpr std::uint64_t kBlockBytes = 64 * 1024;

std::uint64_t add_file(const std::filesystem::path& path, std::uint64_t hash,
                       std::uint64_t* bytes) {
  const std::uint64_t size = input_file_size(path);
  *bytes += size;
  hash = util::fnv1a64(std::string_view(reinterpret_cast<const char*>(&size), sizeof(size)), hash);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(prefix(path) + "cannot open for reading");
  std::vector<char> block(kBlockBytes);
  // Evenly spread blocks, the first at the start (the header) and the last at the end.
  const std::uint64_t span = size > kBlockBytes ? size - kBlockBytes : 0;
  const std::uint64_t blocks = size > kBlockBytes ? kBlocks : 1;
  for (std::uint64_t b = 0; b < blocks; ++b) {
    const std::uint64_t at = blocks > 1 ? span * b / (blocks - 1) : 0;
    const std::uint64_t length = std::min(kBlockBytes, size - at);
    in.seekg(static_cast<std::streamoff>(at));
    if (!in.read(block.data(), static_cast<std::streamsize>(length))) {
      throw InputError(prefix(path) + "read failed");
    }
    hash = util::fnv1a64(std::string_view(block.data(), length), hash);
  }
  return hash;
}

}  // namespace

DataFingerprint data_fingerprint(const std::string& name) {
  std::vector<std::filesystem::path> files;
  if (const auto h5 = split_hdf5_dataset(name)) {
    files.push_back(h5->first);
  } else if (is_stack_path(name)) {
    files = stack_files(name);
  } else {
    files.push_back(name);
  }
  DataFingerprint f;
  f.hash = util::kFnvOffset;
  for (const std::filesystem::path& file : files) f.hash = add_file(file, f.hash, &f.bytes);
  f.files = files.size();
  return f;
}

}  // namespace riner::io
