// A 2D test image painted from a function of each pixel's centre (mm, riner::voxel_centre).
#pragma once

#include <cstddef>

#include "riner/array.hpp"
#include "riner/geometry.hpp"
#include "riner/rays.hpp"

namespace riner::test {

template <class Value>
Array painted(const Geometry& g, const Value& value) {
  Array image(g.volume_shape);
  for (std::size_t i = 0; i < g.volume_shape[0]; ++i) {
    for (std::size_t k = 0; k < g.volume_shape[1]; ++k) {
      image(i, k) = value(voxel_centre(g, static_cast<double>(k), static_cast<double>(i)));
    }
  }
  return image;
}

}  // namespace riner::test
