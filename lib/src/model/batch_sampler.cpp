#include "model/batch_sampler.hpp"

#include <algorithm>
#include <unordered_map>
#include <utility>

#include "model/counter_rng.hpp"
#include "riner/error.hpp"

namespace riner::model {

namespace {

std::uint32_t draw(std::uint32_t seed, std::uint32_t step, std::uint32_t i, std::uint32_t n) {
  // 32-bit hash times n, high word: unbiased enough for n << 2^32 and identical everywhere.
  return static_cast<std::uint32_t>(
      (static_cast<std::uint64_t>(hash_keys(kBatchStream, seed, step, i)) * n) >> 32);
}

}  // namespace

BatchSampler::BatchSampler(const Geometry& g, const TrainingConfig& config,
                           std::vector<std::uint8_t> silent)
    : views_(g.n_views()),
      rows_(g.is_3d() ? g.n_v : 1),
      n_u_(g.n_u),
      config_(config),
      silent_(std::move(silent)) {
  if (!silent_.empty() && silent_.size() != rows_ * n_u_) {
    throw Error("BatchSampler: " + std::to_string(silent_.size()) + " silent flags for " +
                std::to_string(rows_ * n_u_) + " detector elements");
  }
  if (config.sampler != Sampler::kViewsTimesElements && config.rays_per_step < 1) {
    throw Error("BatchSampler: rays_per_step " + std::to_string(config.rays_per_step) +
                " (0 is for the execution plan to resolve first)");
  }
  if (draws_block(config.sampler) && static_cast<std::size_t>(config.elements_per_step) > n_u_) {
    throw InputError("elements_per_step (" + std::to_string(config.elements_per_step) +
                     ") exceeds the detector's " + std::to_string(n_u_) + " elements");
  }
}

std::size_t BatchSampler::rays_per_step() const {
  const auto uniform = static_cast<std::size_t>(config_.rays_per_step);
  const auto block = static_cast<std::size_t>(config_.views_per_step) * config_.elements_per_step;
  switch (config_.sampler) {
    case Sampler::kUniform:
    case Sampler::kEven:
      return uniform;
    case Sampler::kViewsTimesElements:
      return block;
    case Sampler::kMixed:
      return uniform + block;
  }
  return 0;
}

Batch BatchSampler::batch(std::uint32_t step) const {
  const auto seed = static_cast<std::uint32_t>(config_.seed ^ (config_.seed >> 32));
  const std::size_t per_view = rows_ * n_u_;
  Batch b;
  if (config_.sampler == Sampler::kEven) {
    // Ray i of step s is the (s R + i)-th of an endless sequence of epochs, each a shuffled
    // order of all elements.
    const auto n = static_cast<std::uint32_t>(per_view);
    for (int i = 0; i < config_.rays_per_step; ++i) {
      const std::uint64_t position =
          static_cast<std::uint64_t>(step) * static_cast<std::uint64_t>(config_.rays_per_step) +
          static_cast<std::uint64_t>(i);
      const std::uint64_t epoch = position / n;
      const std::uint32_t key = hash_keys(seed, static_cast<std::uint32_t>(epoch),
                                          static_cast<std::uint32_t>(epoch >> 32));
      const std::uint32_t element =
          shuffled_index(static_cast<std::uint32_t>(position % n), n, key);
      const std::uint32_t view =
          draw(seed, step, static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(views_));
      b.rays.push_back(static_cast<std::uint32_t>(view * per_view + element));
      b.elements.push_back(element);
    }
  } else if (config_.sampler != Sampler::kViewsTimesElements) {
    const auto total = static_cast<std::uint32_t>(views_ * per_view);
    for (int i = 0; i < config_.rays_per_step; ++i) {
      b.rays.push_back(draw(seed, step, static_cast<std::uint32_t>(i), total));
    }
    for (std::uint32_t r : b.rays) b.elements.push_back(static_cast<std::uint32_t>(r % per_view));
  }
  if (draws_block(config_.sampler)) {
    b.block_first = static_cast<std::uint32_t>(b.rays.size());
    b.block_views = static_cast<std::uint32_t>(config_.views_per_step);
    b.block_elements = static_cast<std::uint32_t>(config_.elements_per_step);
    // One run of adjacent elements (in one detector row) shared by all the step's views.
    const auto e = static_cast<std::uint32_t>(config_.elements_per_step);
    const std::uint32_t row = draw(seed, step, 0x7fffffffu, static_cast<std::uint32_t>(rows_));
    const std::uint32_t first =
        draw(seed, step, 0x7ffffffeu, static_cast<std::uint32_t>(n_u_ - e + 1));
    for (int i = 0; i < config_.views_per_step; ++i) {
      // Keys above the uniform part's, so the two parts draw independently.
      const std::uint32_t view = draw(seed, step, 0x40000000u + static_cast<std::uint32_t>(i),
                                      static_cast<std::uint32_t>(views_));
      for (std::uint32_t k = 0; k < e; ++k) {
        b.rays.push_back(static_cast<std::uint32_t>(view * per_view + row * n_u_ + first + k));
      }
    }
    for (std::uint32_t k = 0; k < e; ++k)
      b.elements.push_back(static_cast<std::uint32_t>(row * n_u_ + first + k));
  }
  std::sort(b.elements.begin(), b.elements.end());
  b.elements.erase(std::unique(b.elements.begin(), b.elements.end()), b.elements.end());
  const double c = config_.data_weight;
  if (config_.data_term == DataTerm::kElementMean) {
    std::unordered_map<std::uint32_t, int> rays_of;
    for (std::uint32_t r : b.rays) ++rays_of[static_cast<std::uint32_t>(r % per_view)];
    for (std::uint32_t r : b.rays)
      b.weights.push_back(
          static_cast<float>(c / rays_of[static_cast<std::uint32_t>(r % per_view)]));
  } else {
    const double w =
        config_.data_term == DataTerm::kMean ? c / static_cast<double>(b.rays.size()) : c;
    b.weights.assign(b.rays.size(), static_cast<float>(w));
  }
  if (!silent_.empty()) {
    for (std::size_t i = 0; i < b.rays.size(); ++i) {
      if (silent_[b.rays[i] % per_view]) b.weights[i] = 0.0f;
    }
  }
  return b;
}

}  // namespace riner::model
