// Shared checks for readers and writers: a readable regular file, its bytes, and the rule that
// outputs never replace an input.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace riner::io {

// Size of a readable regular file; InputError ("X: no such file", "X: is a directory").
std::uint64_t input_file_size(const std::filesystem::path& path);

// Whole file contents; registers the path as an input.
std::string read_file_bytes(const std::filesystem::path& path);

// InputError when `path` is an input of this process (or the same file through another name)
// or when its directory does not exist.
void check_output_path(const std::filesystem::path& path);

// Number of elements in `shape`; InputError naming the file when it overflows.
std::size_t element_count(const std::filesystem::path& path, const std::vector<std::size_t>& shape);

// The extension in lower case (".TIF" -> ".tif"), for choosing a format.
std::string lower_extension(const std::filesystem::path& path);

// "file.npy: " for error messages.
std::string prefix(const std::filesystem::path& path);

}  // namespace riner::io
