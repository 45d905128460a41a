// The parameter layout, initialisation, ray segments and batch sampler shared by both engines.
#include <doctest/doctest.h>

#include <cstring>

#include <cmath>
#include <map>
#include <vector>

#include "model/batch_sampler.hpp"
#include "model/counter_rng.hpp"
#include "model/packed_batch.hpp"
#include "model/parameter_layout.hpp"
#include "model/ray_segments.hpp"
#include "riner/error.hpp"
#include "riner/rays.hpp"
#include "support/geometries.hpp"

TEST_SUITE("model_layout") {
  TEST_CASE("levels: scale, resolution, dense until the table is full, then hashed") {
    const riner::EncodingConfig enc{4, 2, 10, 4, 32};  // b = 2: scales 3, 7, 15, 31
    const auto l = riner::model::make_layout(2, enc, {16, 1}, 7);
    REQUIRE(l.grid.size() == 4);
    CHECK(l.grid[0].scale == doctest::Approx(3.0));
    CHECK(l.grid[3].scale == doctest::Approx(31.0));
    CHECK(l.grid[0].resolution == 5);   // ceil(3) + 2
    CHECK(l.grid[2].resolution == 17);  // 17^2 = 289 <= 1024: dense
    CHECK(l.grid[2].hashed == 0);
    CHECK(l.grid[3].resolution == 33);  // 33^2 = 1089 > 1024: hashed into 1024 entries
    CHECK(l.grid[3].hashed == 1);
    CHECK(l.grid[1].offset == 25 * 2);
    CHECK(l.grid_params == (25 + 81 + 289 + 1024) * 2u);
    CHECK(l.mlp_params == 8 * 16 + 16 + 16 + 1u);
    CHECK(l.alpha_offset == l.grid_params + l.mlp_params);
    CHECK(l.total == l.beta_offset + 7);
    const auto deep = riner::model::make_layout(3, enc, {32, 3}, 5);
    CHECK(deep.w_hidden(1) == deep.b_in() + 32u);
    CHECK(deep.w_out() == deep.w_hidden(3));
    CHECK(deep.mlp_params == 8 * 32 + 32 + 2 * (32 * 32 + 32) + 32 + 1u);
  }

  TEST_CASE("initial values follow instant-NGP and PyTorch, alpha0 = beta0 = 1") {
    const auto l = riner::model::make_layout(2, {4, 2, 10, 4, 32}, {16, 1}, 7);
    const auto p = riner::model::initial_parameters(l, 42);
    for (std::size_t i = 0; i < l.grid_params; ++i) REQUIRE(std::fabs(p[i]) <= 1e-4f);
    for (std::size_t i = l.w_in(); i < l.b_in(); ++i)
      REQUIRE(std::fabs(p[i]) <= 1.0f / std::sqrt(8.0f));
    for (std::size_t e = 0; e < 7; ++e) {
      CHECK(p[l.alpha_offset + e] == 1.0f);
      CHECK(p[l.beta_offset + e] == 1.0f);
    }
    CHECK(riner::model::initial_parameters(l, 42) == p);
    CHECK(riner::model::initial_parameters(l, 43) != p);
  }

  TEST_CASE("alpha as row x column factors: the block after alpha0, all factors start at 1") {
    const riner::EncodingConfig enc{4, 2, 10, 4, 32};
    const auto plain = riner::model::make_layout(3, enc, {16, 1}, 12);
    CHECK_FALSE(plain.factored_alpha());
    CHECK(plain.beta_offset == plain.alpha_offset + 12);
    const auto l = riner::model::make_layout(3, enc, {16, 1}, 12, 3);
    REQUIRE(l.factored_alpha());
    CHECK(l.factor_rows == 3);
    CHECK(l.factor_columns == 4);
    CHECK(l.factor_offset == l.alpha_offset + 12);
    CHECK(l.beta_offset == l.factor_offset + 7);
    CHECK(l.total == plain.total + 7);
    const auto p = riner::model::initial_parameters(l, 1);
    for (std::size_t i = l.alpha_offset; i < l.total; ++i) CHECK(p[i] == 1.0f);
    CHECK_THROWS_AS(riner::model::make_layout(3, enc, {16, 1}, 12, 5), riner::InputError);
  }

  TEST_CASE("ray segments tile the clipped ray exactly, inside the unit square") {
    const riner::Geometry g = riner::test::small_fan2d();
    const auto segments = riner::model::ray_segments(g, 1.0, false);
    REQUIRE(segments.size() == g.n_views() * g.n_u);
    int hit = 0;
    for (std::size_t r = 0; r < segments.size(); ++r) {
      const auto& s = segments[r];
      const riner::Ray ray = riner::detector_ray(g, r / g.n_u, static_cast<double>(r % g.n_u));
      const riner::Segment clip = riner::clip_to_box(g, ray);
      if (clip.empty()) {
        CHECK(s.count == 0);
        continue;
      }
      ++hit;
      CHECK(s.count == static_cast<std::uint32_t>(std::ceil(clip.length() - 1e-9)));
      CHECK(s.dx * s.count == doctest::Approx(clip.length()).epsilon(1e-5));
      for (std::uint32_t k : {0u, s.count - 1}) {
        float p[3];
        riner::model::sample_position(s, k, 0.5f, p);
        CHECK(p[0] >= 0.0f);
        CHECK(p[0] <= 1.0f);
        CHECK(p[1] >= 0.0f);
        CHECK(p[1] <= 1.0f);
      }
    }
    CHECK(hit > 0);
  }

  TEST_CASE("batches: deterministic per step, in range, weights per the data term") {
    const riner::Geometry g = riner::test::small_fan2d();
    riner::TrainingConfig t;
    t.sampler = riner::Sampler::kMixed;
    t.rays_per_step = 50;
    t.views_per_step = 6;
    t.elements_per_step = 5;
    t.data_weight = 0.2;
    const riner::model::BatchSampler sampler(g, t);
    const auto b = sampler.batch(3);
    REQUIRE(b.rays.size() == 80);
    CHECK(sampler.batch(3).rays == b.rays);
    CHECK(sampler.batch(4).rays != b.rays);
    for (std::uint32_t r : b.rays) CHECK(r < g.n_views() * g.n_u);
    CHECK(b.block_first == 50);
    CHECK(b.block_views == 6);
    CHECK(b.block_elements == 5);
    // The block: same run of 5 adjacent elements in every view.
    for (std::uint32_t v = 0; v < 6; ++v) {
      for (std::uint32_t e = 1; e < 5; ++e) {
        CHECK(b.rays[50 + v * 5 + e] == b.rays[50 + v * 5] + e);
      }
    }
    // Element mean: each element's weights sum to data_weight.
    std::map<std::uint32_t, double> per_element;
    for (std::size_t i = 0; i < b.rays.size(); ++i) per_element[b.rays[i] % g.n_u] += b.weights[i];
    for (const auto& [e, w] : per_element) CHECK(w == doctest::Approx(0.2));
    CHECK(per_element.size() == b.elements.size());

    // Silent elements (stuck ones): the same rays, theirs at weight 0, the rest as they were.
    std::vector<std::uint8_t> silent(g.n_u, 0);
    for (std::size_t e = 0; e < g.n_u; e += 3) silent[e] = 1;
    const auto quiet = riner::model::BatchSampler(g, t, silent).batch(3);
    REQUIRE(quiet.rays == b.rays);
    std::size_t zeroed = 0;
    for (std::size_t i = 0; i < b.rays.size(); ++i) {
      const bool is_silent = silent[b.rays[i] % g.n_u] != 0;
      zeroed += is_silent;
      CHECK(quiet.weights[i] == (is_silent ? 0.0f : b.weights[i]));
    }
    CHECK(zeroed > 0);
    CHECK_THROWS_AS(riner::model::BatchSampler(g, t, std::vector<std::uint8_t>(g.n_u + 1, 0)),
                    riner::Error);
  }

  TEST_CASE("shuffled_index is a permutation of 0..n-1 for every key, and keys differ") {
    for (std::uint32_t n : {1u, 2u, 3u, 7u, 64u, 100u, 1000u, 4097u}) {
      for (std::uint32_t key : {0u, 1u, 12345u}) {
        std::vector<int> seen(n, 0);
        for (std::uint32_t k = 0; k < n; ++k) {
          const std::uint32_t x = riner::model::shuffled_index(k, n, key);
          REQUIRE(x < n);
          ++seen[x];
        }
        for (std::uint32_t i = 0; i < n; ++i) CHECK(seen[i] == 1);
      }
    }
    int moved = 0;
    for (std::uint32_t k = 0; k < 1000; ++k) {
      moved += riner::model::shuffled_index(k, 1000, 1) != riner::model::shuffled_index(k, 1000, 2);
    }
    CHECK(moved > 900);
  }

  TEST_CASE("even sampler: every detector pixel exactly once per epoch, views spread") {
    const riner::Geometry g = riner::test::small_cone3d();
    const std::size_t pixels = g.n_u * g.n_v;
    riner::TrainingConfig t;
    t.sampler = riner::Sampler::kEven;
    t.rays_per_step = 7;  // does not divide the pixel count: epochs straddle steps
    const riner::model::BatchSampler sampler(g, t);
    CHECK(sampler.rays_per_step() == 7);
    CHECK(sampler.batch(5).rays == sampler.batch(5).rays);
    std::vector<int> count(pixels, 0);
    std::vector<int> view_count(g.n_views(), 0);
    const std::size_t epochs = 3;
    const std::size_t rays = epochs * pixels;
    std::size_t drawn = 0;
    for (std::uint32_t step = 0; drawn < rays; ++step) {
      const riner::model::Batch b = sampler.batch(step);
      CHECK(b.block_views == 0);
      for (std::uint32_t r : b.rays) {
        if (drawn++ >= rays) break;
        REQUIRE(r < g.n_views() * pixels);
        ++count[r % pixels];
        ++view_count[r / pixels];
      }
    }
    for (std::size_t p = 0; p < pixels; ++p) CHECK(count[p] == static_cast<int>(epochs));
    int views_hit = 0;
    for (int c : view_count) views_hit += c > 0;
    CHECK(views_hit > static_cast<int>(g.n_views()) * 3 / 4);
  }

  TEST_CASE("packed batches: offsets, rays grouped by element, weights and level scales") {
    const riner::Geometry g = riner::test::small_fan2d();
    riner::TrainingConfig t;
    t.sampler = riner::Sampler::kMixed;
    t.rays_per_step = 300;  // enough that elements repeat
    t.views_per_step = 4;
    t.elements_per_step = 3;
    const riner::model::BatchSampler sampler(g, t);
    const riner::model::Batch b = sampler.batch(7);
    const riner::model::RaySegments segments(g, 1.0, false);
    std::vector<float> rho(g.n_views() * g.n_u);
    for (std::size_t i = 0; i < rho.size(); ++i) rho[i] = 0.001f * static_cast<float>(i);
    riner::model::PackedBatch p;
    riner::model::pack_batch(b, segments, rho, g.n_u, {1.0f, 0.5f, 0.25f}, p);
    const std::vector<std::uint32_t>& w = p.words;
    REQUIRE(p.n_batch == b.rays.size());
    REQUIRE(p.n_elements == b.elements.size());
    std::uint32_t samples = 0;
    for (std::uint32_t i = 0; i < p.n_batch; ++i) {
      CHECK(w[p.rays_at + i] == b.rays[i]);
      CHECK(w[p.offsets_at + i] == samples);
      samples += segments[b.rays[i]].count;
      float weight;
      std::memcpy(&weight, &w[p.weights_at + i], 4);
      CHECK(weight == b.weights[i]);
      // The ray's own segment and reading travel with it.
      const riner::model::RaySegment segment = segments[b.rays[i]];
      CHECK(std::memcmp(&w[p.segments_at + 8 * i], &segment, 32) == 0);
      float reading;
      std::memcpy(&reading, &w[p.rho_at + i], 4);
      CHECK(reading == rho[b.rays[i]]);
    }
    CHECK(w[p.offsets_at + p.n_batch] == samples);
    CHECK(p.n_samples == samples);
    // Every ray once, under its own element, ascending within the element.
    std::vector<int> seen(p.n_batch, 0);
    const std::uint32_t* starts = &w[p.element_rays_at];
    const std::uint32_t* grouped = starts + p.n_elements + 1;
    CHECK(starts[0] == 0);
    CHECK(starts[p.n_elements] == p.n_batch);
    bool repeated = false;
    for (std::uint32_t e = 0; e < p.n_elements; ++e) {
      CHECK(w[p.elements_at + e] == b.elements[e]);
      repeated = repeated || starts[e + 1] - starts[e] > 1;
      for (std::uint32_t j = starts[e]; j < starts[e + 1]; ++j) {
        ++seen[grouped[j]];
        CHECK(b.rays[grouped[j]] % g.n_u == b.elements[e]);
        if (j > starts[e]) CHECK(grouped[j] > grouped[j - 1]);
      }
    }
    CHECK(repeated);
    for (int count : seen) CHECK(count == 1);
    float scale;
    std::memcpy(&scale, &w[p.level_weights_at + 2], 4);
    CHECK(scale == 0.25f);
    CHECK(p.segments_at == p.level_weights_at + 3);
    CHECK(p.rho_at == p.segments_at + 8 * p.n_batch);
    CHECK(w.size() == p.rho_at + p.n_batch);
  }
}
