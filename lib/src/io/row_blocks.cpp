#include "io/row_blocks.hpp"

#include <cmath>

#include "io/file_access.hpp"
#include "riner/error.hpp"

namespace riner::io {

void check_row_range(const std::filesystem::path& path, const std::vector<std::size_t>& shape,
                     RowRange rows) {
  if (shape.size() != 3) {
    throw InputError(prefix(path) + "is " + shape_string(shape) +
                     "; reading detector rows needs a stack [views, rows, columns]");
  }
  if (rows.count == 0 || rows.first > shape[1] || rows.count > shape[1] - rows.first) {
    throw InputError(prefix(path) + "has " + std::to_string(shape[1]) + " detector rows; rows " +
                     std::to_string(rows.first) + ".." +
                     std::to_string(rows.first + rows.count) + " asked for");
  }
}

ArrayFile read_row_blocks(std::ifstream& in, const std::filesystem::path& path,
                          std::size_t data_start, const std::vector<std::size_t>& shape,
                          RowRange rows, SampleType type, bool little_endian, FileFormat format) {
  const std::size_t frames = shape[0];
  const std::size_t cols = shape[2];
  const std::size_t item = sample_bytes(type);
  const std::size_t block = rows.count * cols;
  ArrayFile file;
  file.format = format;
  file.dtype = sample_type_name(type);
  file.array = Array({frames, rows.count, cols});
  std::vector<unsigned char> bytes(block * item);
  for (std::size_t f = 0; f < frames; ++f) {
    const std::size_t offset = data_start + ((f * shape[1] + rows.first) * cols) * item;
    in.seekg(static_cast<std::streamoff>(offset));
    in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    if (!in) {
      throw InputError(prefix(path) + "truncated or unreadable at frame " + std::to_string(f));
    }
    file.non_finite += decode_samples(bytes.data(), block, type, little_endian,
                                      file.array.ptr() + f * block);
  }
  return file;
}

ArrayFile cut_rows(ArrayFile whole, const std::filesystem::path& path, RowRange rows) {
  check_row_range(path, whole.array.shape, rows);
  const std::vector<std::size_t>& shape = whole.array.shape;
  if (rows.first == 0 && rows.count == shape[1]) return whole;
  const std::size_t cols = shape[2];
  Array cut({shape[0], rows.count, cols});
  std::size_t non_finite = 0;
  for (std::size_t f = 0; f < shape[0]; ++f) {
    const float* from = whole.array.ptr() + (f * shape[1] + rows.first) * cols;
    float* to = cut.ptr() + f * rows.count * cols;
    for (std::size_t i = 0; i < rows.count * cols; ++i) {
      to[i] = from[i];
      non_finite += !std::isfinite(from[i]);
    }
  }
  whole.array = std::move(cut);
  whole.non_finite = non_finite;
  return whole;
}

}  // namespace riner::io
