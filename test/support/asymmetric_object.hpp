// An object with no symmetry about the grid centre (a bar, a disc and a ramp): its views half a
// turn apart are mirror images only about the axis, and no two views a quarter-turn apart match.
#pragma once

#include <cmath>
#include <vector>

#include "riner/array.hpp"

namespace riner::test {

inline Array asymmetric_object(const std::vector<std::size_t>& shape) {
  Array a(shape);
  const std::size_t ny = shape[shape.size() - 2], nx = shape.back();
  const std::size_t slices = shape.size() == 3 ? shape[0] : 1;
  for (std::size_t z = 0; z < slices; ++z) {
    for (std::size_t i = 0; i < ny; ++i) {
      for (std::size_t k = 0; k < nx; ++k) {
        const double x = static_cast<double>(k) - 0.5 * nx, y = static_cast<double>(i) - 0.5 * ny;
        float v = 0.0f;
        if (x > 4 && x < 12 && y > -14 && y < 6) v += 0.02f;
        if (std::hypot(x + 8, y - 7) < 5) v += 0.03f;
        if (std::hypot(x, y) < 0.4 * nx) v += 0.005f * static_cast<float>(1.0 + x / nx + 0.1 * z);
        a.data[(z * ny + i) * nx + k] = v;
      }
    }
  }
  return a;
}

}  // namespace riner::test
