// A separable filter over an image or volume of any rank: a 1D filter on every line along each
// axis in turn, the last (fastest) first, each pass reading the one before.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

#include "util/parallel.hpp"

namespace riner::util {

// filter(in, out, n, stride): a line's n values are in[i * stride], its results go to
// out[i * stride]. Lines run in parallel.
template <typename Filter>
std::vector<float> along_each_axis(std::vector<float> data, const std::vector<std::size_t>& shape,
                                   Filter filter) {
  std::vector<float> out(data.size());
  std::size_t stride = 1;
  for (std::size_t axis = shape.size(); axis-- > 0;) {
    const std::size_t n = shape[axis];
    parallel_for(data.size() / n, [&](std::size_t begin, std::size_t end) {
      for (std::size_t line = begin; line < end; ++line) {
        // The line's first value: `line` counts the other axes, this one's stride left out.
        const std::size_t base = (line / stride) * stride * n + line % stride;
        filter(data.data() + base, out.data() + base, n, stride);
      }
    });
    std::swap(data, out);
    stride *= n;
  }
  return data;
}

}  // namespace riner::util
