// Where every trainable number lives in the one flat parameter buffer both engines share:
//   [hash-grid tables | MLP | alpha0 per element | alpha's row and column factors | beta0 per
//    element]
// The factor block is there only for a rows-times-columns alpha (kernels/alpha_factors.cl):
// alpha0 of element (r, c) is then row factor r times column factor c, the factors are what
// Adam trains, and alpha0 per element is their product, kept where the step reads it.
// Grid: level l holds entries(l) x features floats from levels[l].offset; entry e, feature f at
// offset + e * features + f. MLP: W_in [inputs][width], b_in [width], then per extra hidden
// layer W [width][width], b [width], then W_out [width], b_out [1] (row-major).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "riner/riner_config.hpp"

namespace riner::model {

// Host mirror of GridLevel in kernels/hash_grid.cl (four 4-byte members).
struct GridLevel {
  float scale;               // positions map to x * scale + 0.5 in grid units
  std::uint32_t resolution;  // vertices per axis
  std::uint32_t offset;      // first float of the level in the parameter buffer
  std::uint32_t hashed;      // 1: index = spatial hash mod table size; 0: dense
};
static_assert(sizeof(GridLevel) == 16);

struct ParameterLayout {
  int dims = 2;
  int levels = 0;
  int features = 0;
  std::uint32_t table_size = 0;  // entries of a hashed level
  int inputs = 0;                // levels * features
  int width = 0;
  int hidden_layers = 1;
  std::vector<GridLevel> grid;
  std::size_t grid_params = 0;
  std::size_t mlp_offset = 0;
  std::size_t mlp_params = 0;
  std::size_t alpha_offset = 0;
  std::size_t factor_offset = 0;  // row factors, then column factors (alpha_offset + elements)
  std::size_t factor_rows = 0;    // 0: alpha0 per element is trained directly
  std::size_t factor_columns = 0;
  std::size_t beta_offset = 0;
  std::size_t elements = 0;
  std::size_t total = 0;

  // Offsets of the MLP's pieces inside the whole buffer.
  std::size_t w_in() const { return mlp_offset; }
  std::size_t b_in() const { return w_in() + static_cast<std::size_t>(inputs) * width; }
  std::size_t w_hidden(int layer) const;  // layer = 1 .. hidden_layers - 1
  std::size_t b_hidden(int layer) const {
    return w_hidden(layer) + static_cast<std::size_t>(width) * width;
  }
  std::size_t w_out() const;
  std::size_t b_out() const { return w_out() + static_cast<std::size_t>(width); }
  bool factored_alpha() const { return factor_rows > 0; }
};

// alpha_rows > 0: alpha as row x column factors over a detector of alpha_rows rows (elements
// must be a multiple of it).
ParameterLayout make_layout(int dims, const EncodingConfig& encoding, const NetworkConfig& network,
                            std::size_t elements, std::size_t alpha_rows = 0);

// Initial values: grid U(-1e-4, 1e-4) (instant-NGP), MLP weights and biases
// U(-1/sqrt(fan_in), 1/sqrt(fan_in)) (PyTorch's nn.Linear), alpha0 = beta0 = 1 (the paper),
// alpha's factors 1.
std::vector<float> initial_parameters(const ParameterLayout& layout, std::uint64_t seed);

}  // namespace riner::model
