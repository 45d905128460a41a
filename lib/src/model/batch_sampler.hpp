// Which rays each training step uses (METHOD.md §2). Draws are counter-based on (seed, step),
// so step n's batch does not depend on what ran before, and both engines see the same rays.
#pragma once

#include <cstdint>
#include <vector>

#include "riner/geometry.hpp"
#include "riner/riner_config.hpp"

namespace riner::model {

struct Batch {
  std::vector<std::uint32_t> rays;      // ray ids: (view * rows + row) * n_u + element
  std::vector<std::uint32_t> elements;  // the distinct detector elements (row * n_u + u) hit
  std::vector<float> weights;           // data-term weight of each ray (TrainingConfig::data_term)
  // The views x elements block: rays[block_first + v * block_elements + e] is element e of the
  // run in the block's view v (none when block_views is 0).
  std::uint32_t block_first = 0;
  std::uint32_t block_views = 0;
  std::uint32_t block_elements = 0;
};

class BatchSampler {
 public:
  // silent: per element (row-major [rows, columns]), 1 where the element's readings say nothing
  // (stuck elements, model/stuck_elements.hpp): its rays are drawn as usual but weigh 0, since
  // read as 0 they would pull the field to 0. Empty: none.
  BatchSampler(const Geometry& g, const TrainingConfig& config,
               std::vector<std::uint8_t> silent = {});
  Batch batch(std::uint32_t step) const;
  std::size_t rays_per_step() const;

 private:
  std::size_t views_;
  std::size_t rows_;
  std::size_t n_u_;
  TrainingConfig config_;
  std::vector<std::uint8_t> silent_;
};

}  // namespace riner::model
