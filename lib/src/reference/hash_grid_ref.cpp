#include "reference/hash_grid_ref.hpp"

#include <algorithm>
#include <cmath>

namespace riner::ref {

namespace {

constexpr std::uint32_t kPrimes[3] = {1u, 2654435761u, 805459861u};

// Visits the 2^dims vertices around pos at one level: visit(param_index, weight).
template <typename Visit>
void for_each_vertex(const model::ParameterLayout& l, int level, const double* pos, Visit&& visit) {
  const model::GridLevel& g = l.grid[static_cast<std::size_t>(level)];
  std::uint32_t cell[3] = {0, 0, 0};
  double frac[3] = {0, 0, 0};
  for (int d = 0; d < l.dims; ++d) {
    const double x = std::clamp(pos[d], 0.0, 1.0) * static_cast<double>(g.scale) + 0.5;
    const double f = std::floor(x);
    cell[d] = static_cast<std::uint32_t>(f);
    frac[d] = x - f;
  }
  for (int corner = 0; corner < (1 << l.dims); ++corner) {
    std::uint32_t coords[3] = {0, 0, 0};
    double weight = 1.0;
    for (int d = 0; d < l.dims; ++d) {
      const bool upper = (corner >> d) & 1;
      coords[d] = cell[d] + (upper ? 1u : 0u);
      weight *= upper ? frac[d] : 1.0 - frac[d];
    }
    visit(hash_grid_index(l, level, coords), weight);
  }
}

}  // namespace

std::uint32_t hash_grid_index(const model::ParameterLayout& l, int level,
                              const std::uint32_t* coords) {
  const model::GridLevel& g = l.grid[static_cast<std::size_t>(level)];
  std::uint32_t index = 0;
  if (g.hashed) {
    for (int d = 0; d < l.dims; ++d) index ^= coords[d] * kPrimes[d];
    index %= l.table_size;
  } else {
    std::uint32_t stride = 1;
    for (int d = 0; d < l.dims; ++d) {
      index += coords[d] * stride;
      stride *= g.resolution;
    }
  }
  return g.offset + index * static_cast<std::uint32_t>(l.features);
}

void hash_grid_encode(const model::ParameterLayout& l, const double* params, const double* pos,
                      double* out) {
  for (int level = 0; level < l.levels; ++level) {
    double* o = out + level * l.features;
    std::fill(o, o + l.features, 0.0);
    for_each_vertex(l, level, pos, [&](std::uint32_t index, double w) {
      for (int f = 0; f < l.features; ++f) o[f] += w * params[index + f];
    });
  }
}

void hash_grid_scatter(const model::ParameterLayout& l, const double* pos, const double* d_out,
                       double* grad) {
  for (int level = 0; level < l.levels; ++level) {
    const double* d = d_out + level * l.features;
    for_each_vertex(l, level, pos, [&](std::uint32_t index, double w) {
      for (int f = 0; f < l.features; ++f) grad[index + f] += w * d[f];
    });
  }
}

std::vector<float> hash_grid_forward(const model::ParameterLayout& l,
                                     const std::vector<float>& params,
                                     const std::vector<float>& positions) {
  const std::vector<double> p(params.begin(), params.end());
  const std::size_t n = positions.size() / static_cast<std::size_t>(l.dims);
  std::vector<float> out(n * static_cast<std::size_t>(l.inputs));
  std::vector<double> features(static_cast<std::size_t>(l.inputs));
  for (std::size_t i = 0; i < n; ++i) {
    double pos[3] = {0, 0, 0};
    for (int d = 0; d < l.dims; ++d) pos[d] = positions[i * l.dims + d];
    hash_grid_encode(l, p.data(), pos, features.data());
    std::copy(features.begin(), features.end(), out.begin() + static_cast<long>(i * l.inputs));
  }
  return out;
}

std::vector<double> hash_grid_backward(const model::ParameterLayout& l,
                                       const std::vector<float>& positions,
                                       const std::vector<float>& d_features) {
  std::vector<double> grad(l.total, 0.0);
  const std::size_t n = positions.size() / static_cast<std::size_t>(l.dims);
  std::vector<double> d(static_cast<std::size_t>(l.inputs));
  for (std::size_t i = 0; i < n; ++i) {
    double pos[3] = {0, 0, 0};
    for (int k = 0; k < l.dims; ++k) pos[k] = positions[i * l.dims + k];
    for (int k = 0; k < l.inputs; ++k)
      d[static_cast<std::size_t>(k)] = d_features[i * l.inputs + k];
    hash_grid_scatter(l, pos, d.data(), grad.data());
  }
  return grad;
}

}  // namespace riner::ref
