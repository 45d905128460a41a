// A training step's batch as one block of 32-bit words, so that it reaches the device in one
// upload (layout: kernels/sample_cache.cl): the rays, their sample offsets and weights, the
// rays grouped by detector element (so that one work-item adds up an element's gradient, in
// a fixed order), the encoding's level scales, and each ray's segment and reading (the scan's
// tables stay on the host).
#pragma once

#include <cstdint>
#include <vector>

#include "model/batch_sampler.hpp"
#include "model/ray_segments.hpp"

namespace riner::model {

struct PackedBatch {
  std::vector<std::uint32_t> words;
  std::uint32_t n_batch = 0;
  std::uint32_t n_samples = 0;
  std::uint32_t n_elements = 0;
  // Where each section starts in words.
  std::uint32_t rays_at = 0;
  std::uint32_t offsets_at = 0;
  std::uint32_t weights_at = 0;
  std::uint32_t element_rays_at = 0;
  std::uint32_t elements_at = 0;
  std::uint32_t level_weights_at = 0;
  std::uint32_t segments_at = 0;  // 8 words per ray
  std::uint32_t rho_at = 0;
};

// Fills `out` (reusing its storage). batch.elements must be the sorted distinct elements of
// batch.rays (BatchSampler's contract); segments and rho hold every ray of the scan.
void pack_batch(const Batch& batch, const RaySegments& segments, const std::vector<float>& rho,
                std::size_t elements_per_view, const std::vector<float>& level_weights,
                PackedBatch& out);

}  // namespace riner::model
