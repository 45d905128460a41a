// A dense float32 N-d array in C order (last axis fastest): the one in-memory form of every
// sinogram, projection stack, image and volume riner handles.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace riner {

struct Array {
  std::vector<std::size_t> shape;
  std::vector<float> data;

  Array() = default;
  explicit Array(std::vector<std::size_t> shape_, float fill = 0.0f);
  Array(std::vector<std::size_t> shape_, std::vector<float> data_);

  std::size_t rank() const { return shape.size(); }
  std::size_t size() const { return data.size(); }
  float* ptr() { return data.data(); }
  const float* ptr() const { return data.data(); }

  // 2D and 3D element access (row-major); no bounds checks in release builds.
  float& operator()(std::size_t i, std::size_t j) { return data[i * shape[1] + j]; }
  float operator()(std::size_t i, std::size_t j) const { return data[i * shape[1] + j]; }
  float& operator()(std::size_t i, std::size_t j, std::size_t k) {
    return data[(i * shape[1] + j) * shape[2] + k];
  }
  float operator()(std::size_t i, std::size_t j, std::size_t k) const {
    return data[(i * shape[1] + j) * shape[2] + k];
  }
};

// Number of elements a shape holds; throws InputError if the product overflows.
std::size_t shape_size(const std::vector<std::size_t>& shape);

// InputError naming `what` unless `a` holds exactly the values its shape says: its fields are
// public, and a shape that says more than the data holds sent the steps reading past its end.
void check_array(const Array& a, std::string_view what);

// Slice z of a volume [z, y, x] as a 2D image [y, x] (a copy).
Array axial_slice(const Array& volume, std::size_t z);

// Entries [first, first + count) along the first axis (slices of a volume, rows of a map): a
// copy. InputError past the end.
Array first_axis_range(const Array& a, std::size_t first, std::size_t count);

// Detector row `row` of a stack [frames, rows, columns]: [frames, columns] (a copy).
// InputError when there is no such row.
Array detector_row(const Array& stack, std::size_t row);

// Detector rows [first, first + count) of a stack: what a slab of the volume needs.
struct RowRange {
  std::size_t first = 0;
  std::size_t count = 0;
  std::size_t end() const { return first + count; }
  bool operator==(const RowRange& o) const { return first == o.first && count == o.count; }
};

// Detector rows `rows` of a stack: [frames, count, columns] (a copy). InputError past the end.
Array detector_rows(const Array& stack, RowRange rows);

// "[360, 500]"
std::string shape_string(const std::vector<std::size_t>& shape);

struct ArrayStats {
  std::size_t count = 0;
  std::size_t finite = 0;
  std::size_t nan = 0;
  std::size_t pos_inf = 0;
  std::size_t neg_inf = 0;
  double min = 0.0;  // over finite values; 0 when there are none
  double max = 0.0;
  double mean = 0.0;
  double stddev = 0.0;
  std::size_t non_finite() const { return nan + pos_inf + neg_inf; }
};

ArrayStats compute_stats(const Array& array);

}  // namespace riner
