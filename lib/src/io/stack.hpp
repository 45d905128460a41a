// Stacks of 2D images: a folder of TIFFs, or a wildcard pattern in the file name
// ("tiffs/raw_*.tif"), read in natural order (raw_2 before raw_10) as [files, rows, cols].
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "riner/io.hpp"

namespace riner::io {

// A folder, or a name holding *, ? or [.
bool is_stack_path(const std::filesystem::path& path);

// Digit runs compared as numbers: "raw_2" < "raw_10", "a01" and "a1" next to each other.
bool natural_less(const std::string& a, const std::string& b);

// The files a stack path names, in natural order; InputError when there are none.
std::vector<std::filesystem::path> stack_files(const std::filesystem::path& path);

// Every file read with `read_one` (2D each, all the same shape) stacked along a new first axis.
ArrayFile read_stack(const std::filesystem::path& path,
                     ArrayFile (*read_one)(const std::filesystem::path&));

// Rows `rows` of every file (TIFFs, read row by row): [files, count, cols].
ArrayFile read_stack_rows(const std::filesystem::path& path, RowRange rows);
// [files, rows, cols] from the first file's header.
std::vector<std::size_t> stack_shape(const std::filesystem::path& path);

}  // namespace riner::io
