#include "model/parameter_layout.hpp"

#include <cmath>

#include "model/counter_rng.hpp"
#include "riner/error.hpp"

namespace riner::model {

std::size_t ParameterLayout::w_hidden(int layer) const {
  return b_in() + static_cast<std::size_t>(width) +
         static_cast<std::size_t>(layer - 1) * (static_cast<std::size_t>(width) * width + width);
}

std::size_t ParameterLayout::w_out() const { return w_hidden(hidden_layers); }

ParameterLayout make_layout(int dims, const EncodingConfig& encoding, const NetworkConfig& network,
                            std::size_t elements, std::size_t alpha_rows) {
  if (alpha_rows > 0 && elements % alpha_rows != 0)
    throw InputError("alpha's factors: the detector's elements are not rows x columns");
  ParameterLayout l;
  l.dims = dims;
  l.levels = encoding.levels;
  l.features = encoding.features;
  // A config the Reconstructor did not resolve: the slice's table.
  l.table_size = 1u << encoding.log2_table_for(false);
  l.inputs = encoding.levels * encoding.features;
  l.width = network.width;
  l.hidden_layers = network.hidden_layers;
  // b such that the last level's scale + 1 is the finest resolution (instant-NGP's b).
  const double growth = encoding.levels > 1
                            ? std::exp((std::log(static_cast<double>(encoding.finest_resolution)) -
                                        std::log(static_cast<double>(encoding.base_resolution))) /
                                       (encoding.levels - 1))
                            : 1.0;
  std::size_t offset = 0;
  for (int level = 0; level < encoding.levels; ++level) {
    GridLevel g{};
    const double scale = encoding.base_resolution * std::pow(growth, level) - 1.0;
    g.scale = static_cast<float>(scale);
    // One vertex more than instant-NGP's ceil(scale) + 1: positions x * scale + 0.5 reach
    // floor(scale + 0.5) + 1 <= ceil(scale) + 1, which must still be a vertex.
    g.resolution = static_cast<std::uint32_t>(std::ceil(scale)) + 2;
    double entries = std::pow(static_cast<double>(g.resolution), dims);
    g.hashed = entries > l.table_size ? 1u : 0u;
    if (g.hashed) entries = l.table_size;
    g.offset = static_cast<std::uint32_t>(offset);
    offset += static_cast<std::size_t>(entries) * encoding.features;
    l.grid.push_back(g);
  }
  l.grid_params = offset;
  l.mlp_offset = offset;
  l.mlp_params = static_cast<std::size_t>(l.inputs) * l.width + l.width +
                 static_cast<std::size_t>(l.hidden_layers - 1) *
                     (static_cast<std::size_t>(l.width) * l.width + l.width) +
                 l.width + 1;
  l.alpha_offset = l.mlp_offset + l.mlp_params;
  l.factor_offset = l.alpha_offset + elements;
  l.factor_rows = alpha_rows;
  l.factor_columns = alpha_rows > 0 ? elements / alpha_rows : 0;
  l.beta_offset = l.factor_offset + l.factor_rows + l.factor_columns;
  l.elements = elements;
  l.total = l.beta_offset + elements;
  if (l.total >= (std::size_t{1} << 32))
    throw InputError("the model has more than 2^32 parameters");
  return l;
}

std::vector<float> initial_parameters(const ParameterLayout& l, std::uint64_t seed) {
  std::vector<float> p(l.total);
  const auto s = static_cast<std::uint32_t>(seed ^ (seed >> 32));
  auto uniform = [&](std::size_t i, float bound) {
    const float u = uniform24(hash_keys(kInitStream, s, static_cast<std::uint32_t>(i)));
    return bound * (2.0f * u - 1.0f);
  };
  for (std::size_t i = 0; i < l.grid_params; ++i) p[i] = uniform(i, 1e-4f);
  auto linear = [&](std::size_t weights, std::size_t count, std::size_t bias,
                    std::size_t bias_count, int fan_in) {
    const float bound = 1.0f / std::sqrt(static_cast<float>(fan_in));
    for (std::size_t i = 0; i < count; ++i) p[weights + i] = uniform(weights + i, bound);
    for (std::size_t i = 0; i < bias_count; ++i) p[bias + i] = uniform(bias + i, bound);
  };
  linear(l.w_in(), static_cast<std::size_t>(l.inputs) * l.width, l.b_in(), l.width, l.inputs);
  for (int h = 1; h < l.hidden_layers; ++h) {
    linear(l.w_hidden(h), static_cast<std::size_t>(l.width) * l.width, l.b_hidden(h), l.width,
           l.width);
  }
  linear(l.w_out(), l.width, l.b_out(), 1, l.width);
  for (std::size_t e = 0; e < l.elements; ++e) {
    p[l.alpha_offset + e] = 1.0f;
    p[l.beta_offset + e] = 1.0f;
  }
  for (std::size_t f = l.factor_offset; f < l.beta_offset; ++f) p[f] = 1.0f;
  return p;
}

}  // namespace riner::model
