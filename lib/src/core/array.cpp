#include "riner/array.hpp"

#include <algorithm>

#include <cmath>
#include <limits>

#include "riner/error.hpp"

namespace riner {

std::size_t shape_size(const std::vector<std::size_t>& shape) {
  std::size_t n = 1;
  for (std::size_t d : shape) {
    if (d != 0 && n > std::numeric_limits<std::size_t>::max() / d) {
      throw InputError("array shape " + shape_string(shape) + " is too large");
    }
    n *= d;
  }
  return n;
}

std::string shape_string(const std::vector<std::size_t>& shape) {
  std::string s = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + "]";
}

Array::Array(std::vector<std::size_t> shape_, float fill)
    : shape(std::move(shape_)), data(shape_size(shape), fill) {}

Array::Array(std::vector<std::size_t> shape_, std::vector<float> data_)
    : shape(std::move(shape_)), data(std::move(data_)) {
  if (shape_size(shape) != data.size()) {
    throw InputError("array shape " + shape_string(shape) + " does not match " +
                     std::to_string(data.size()) + " values");
  }
}

ArrayStats compute_stats(const Array& array) {
  ArrayStats stats;
  stats.count = array.size();
  double sum = 0.0;
  double sum_sq = 0.0;
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (float v : array.data) {
    if (std::isnan(v)) {
      ++stats.nan;
    } else if (std::isinf(v)) {
      ++(v > 0 ? stats.pos_inf : stats.neg_inf);
    } else {
      ++stats.finite;
      sum += v;
      sum_sq += static_cast<double>(v) * v;
      lo = std::min(lo, static_cast<double>(v));
      hi = std::max(hi, static_cast<double>(v));
    }
  }
  if (stats.finite > 0) {
    stats.min = lo;
    stats.max = hi;
    stats.mean = sum / static_cast<double>(stats.finite);
    const double var = sum_sq / static_cast<double>(stats.finite) - stats.mean * stats.mean;
    stats.stddev = std::sqrt(std::max(0.0, var));
  }
  return stats;
}

void check_array(const Array& a, std::string_view what) {
  if (a.data.size() != shape_size(a.shape)) {
    throw InputError(std::string(what) + ": its shape " + shape_string(a.shape) + " holds " +
                     std::to_string(shape_size(a.shape)) + " values, its data " +
                     std::to_string(a.data.size()));
  }
}

Array first_axis_range(const Array& a, std::size_t first, std::size_t count) {
  if (a.rank() < 1 || first > a.shape[0] || count > a.shape[0] - first) {
    throw InputError("no entries " + std::to_string(first) + ".." + std::to_string(first + count) +
                     " in an array of shape " + shape_string(a.shape));
  }
  const std::size_t each = a.shape[0] ? a.size() / a.shape[0] : 0;
  std::vector<std::size_t> shape = a.shape;
  shape[0] = count;
  const auto begin = a.data.begin() + static_cast<std::ptrdiff_t>(first * each);
  return Array(shape, std::vector<float>(begin, begin + static_cast<std::ptrdiff_t>(count * each)));
}

Array axial_slice(const Array& volume, std::size_t z) {
  if (volume.rank() != 3 || z >= volume.shape[0]) {
    throw InputError("no slice " + std::to_string(z) + " in an array of shape " +
                     shape_string(volume.shape));
  }
  const std::size_t pixels = volume.shape[1] * volume.shape[2];
  const auto first = volume.data.begin() + static_cast<std::ptrdiff_t>(z * pixels);
  return Array({volume.shape[1], volume.shape[2]},
               std::vector<float>(first, first + static_cast<std::ptrdiff_t>(pixels)));
}

Array detector_row(const Array& stack, std::size_t row) {
  if (stack.rank() != 3) {
    throw InputError(
        "a detector row is picked from a projection stack [views, rows, columns]; "
        "this is " +
        shape_string(stack.shape) + ", one sinogram or image");
  }
  if (row >= stack.shape[1]) {
    throw InputError("no detector row " + std::to_string(row) + ": the stack " +
                     shape_string(stack.shape) + " has rows 0.." +
                     std::to_string(stack.shape[1] - 1));
  }
  const std::size_t frames = stack.shape[0], rows = stack.shape[1], columns = stack.shape[2];
  Array out({frames, columns});
  for (std::size_t f = 0; f < frames; ++f) {
    std::copy_n(stack.data.begin() + static_cast<std::ptrdiff_t>((f * rows + row) * columns),
                columns, out.data.begin() + static_cast<std::ptrdiff_t>(f * columns));
  }
  return out;
}

Array detector_rows(const Array& stack, RowRange rows) {
  if (stack.rank() != 3 || rows.count == 0 || rows.end() > stack.shape[1]) {
    throw InputError("no detector rows " + std::to_string(rows.first) + ".." +
                     std::to_string(rows.end()) + " in frames of shape " +
                     shape_string(stack.shape));
  }
  const std::size_t frames = stack.shape[0], all = stack.shape[1], columns = stack.shape[2];
  Array out({frames, rows.count, columns});
  for (std::size_t f = 0; f < frames; ++f) {
    std::copy_n(stack.data.begin() + static_cast<std::ptrdiff_t>((f * all + rows.first) * columns),
                rows.count * columns,
                out.data.begin() + static_cast<std::ptrdiff_t>(f * rows.count * columns));
  }
  return out;
}

}  // namespace riner
