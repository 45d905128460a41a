#include "model/packed_batch.hpp"

#include <algorithm>
#include <cstring>

#include "riner/error.hpp"

namespace riner::model {

namespace {

std::uint32_t bits(float v) {
  std::uint32_t u = 0;
  std::memcpy(&u, &v, sizeof(u));
  return u;
}

}  // namespace

void pack_batch(const Batch& batch, const RaySegments& segments, const std::vector<float>& rho,
                std::size_t elements_per_view, const std::vector<float>& level_weights,
                PackedBatch& out) {
  static_assert(sizeof(RaySegment) == 8 * sizeof(std::uint32_t));
  const auto n = static_cast<std::uint32_t>(batch.rays.size());
  const auto e = static_cast<std::uint32_t>(batch.elements.size());
  out.n_batch = n;
  out.n_elements = e;
  out.rays_at = 0;
  out.offsets_at = n;
  out.weights_at = 2 * n + 1;
  out.element_rays_at = 3 * n + 1;
  out.elements_at = out.element_rays_at + e + 1 + n;
  out.level_weights_at = out.elements_at + e;
  out.segments_at = out.level_weights_at + static_cast<std::uint32_t>(level_weights.size());
  out.rho_at = out.segments_at + 8 * n;
  std::vector<std::uint32_t>& w = out.words;
  w.assign(out.rho_at + n, 0);
  std::uint32_t samples = 0;
  for (std::uint32_t b = 0; b < n; ++b) {
    const std::uint32_t ray = batch.rays[b];
    w[out.rays_at + b] = ray;
    w[out.offsets_at + b] = samples;
    const RaySegment segment = segments[ray];
    samples += segment.count;
    w[out.weights_at + b] = bits(batch.weights[b]);
    std::memcpy(w.data() + out.segments_at + 8 * b, &segment, sizeof(RaySegment));
    w[out.rho_at + b] = bits(rho[ray]);
  }
  w[out.offsets_at + n] = samples;
  out.n_samples = samples;
  // Counting sort of the rays by element; ascending ray index within an element.
  std::uint32_t* starts = w.data() + out.element_rays_at;
  std::uint32_t* grouped = starts + e + 1;
  auto element_index = [&](std::uint32_t b) {
    const auto element = static_cast<std::uint32_t>(batch.rays[b] % elements_per_view);
    const auto it = std::lower_bound(batch.elements.begin(), batch.elements.end(), element);
    if (it == batch.elements.end() || *it != element)
      throw Error("pack_batch: a ray's element is missing from the batch's element list");
    return static_cast<std::uint32_t>(it - batch.elements.begin());
  };
  for (std::uint32_t b = 0; b < n; ++b) ++starts[element_index(b) + 1];
  for (std::uint32_t i = 0; i < e; ++i) starts[i + 1] += starts[i];
  std::vector<std::uint32_t> next(starts, starts + e);
  for (std::uint32_t b = 0; b < n; ++b) grouped[next[element_index(b)]++] = b;
  std::copy(batch.elements.begin(), batch.elements.end(), w.begin() + out.elements_at);
  for (std::size_t l = 0; l < level_weights.size(); ++l)
    w[out.level_weights_at + l] = bits(level_weights[l]);
}

}  // namespace riner::model
