// Reading a range of detector rows of a stack [frames, rows, cols] stored in C order: one block
// of rows per frame, each read with one seek, so a slab costs its own bytes and not the scan's.
#pragma once

#include <filesystem>
#include <fstream>
#include <vector>

#include "io/sample_type.hpp"
#include "riner/io.hpp"

namespace riner::io {

// InputError naming the file when `shape` is not [frames, rows, cols] or `rows` runs past it.
void check_row_range(const std::filesystem::path& path, const std::vector<std::size_t>& shape,
                     RowRange rows);

// The rows of every frame, from C-order samples starting at byte `data_start`.
ArrayFile read_row_blocks(std::ifstream& in, const std::filesystem::path& path,
                          std::size_t data_start, const std::vector<std::size_t>& shape,
                          RowRange rows, SampleType type, bool little_endian, FileFormat format);

// The rows of a stack read whole (formats without a layout that allows seeking).
ArrayFile cut_rows(ArrayFile whole, const std::filesystem::path& path, RowRange rows);

}  // namespace riner::io
