// PSNR/SSIM against scikit-image's values on committed fixtures
// (test/fixtures/make_metrics_fixtures.py), plus properties.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include <nlohmann/json.hpp>

#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/metrics.hpp"
#include "support/fixture.hpp"

namespace {
const std::filesystem::path kFixtures =
    std::filesystem::path(RINER_SOURCE_DIR) / "test/fixtures/metrics";
}

TEST_SUITE("metrics") {
  TEST_CASE("PSNR and SSIM match scikit-image to 1e-4 (2D square, 2D odd rectangle, 3D)") {
    const auto expected = nlohmann::json::parse(riner::read_text(kFixtures / "expected.json"));
    for (const auto& c : expected["cases"]) {
      const std::string name = c["name"];
      CAPTURE(name);
      const riner::Array image = riner::read_array(kFixtures / (name + "_image.npy")).array;
      const riner::Array reference = riner::read_array(kFixtures / (name + "_reference.npy")).array;
      const riner::ImageMetrics m = riner::compare_images(image, reference);
      // scikit-image takes max - min in float32; riner in double.
      CHECK(m.data_range == doctest::Approx(c["data_range"].get<double>()).epsilon(1e-6));
      CHECK(std::fabs(m.psnr - c["psnr"].get<double>()) < 1e-4);
      CHECK(std::fabs(m.ssim - c["ssim"].get<double>()) < 1e-4);
    }
  }

  TEST_CASE("identical images: infinite PSNR, SSIM 1, zero errors") {
    riner::Array a({16, 16});
    for (std::size_t i = 0; i < a.size(); ++i) a.data[i] = static_cast<float>(i % 7);
    const riner::ImageMetrics m = riner::compare_images(a, a);
    CHECK(std::isinf(m.psnr));
    CHECK(m.ssim == doctest::Approx(1.0));
    CHECK(m.mae == 0.0);
  }

  TEST_CASE("edge ratio: 1 for the reference itself, about half for an edge spread over 6 px") {
    // A disc of radius 20 px; the image's edge ramps linearly over `width` px.
    auto disc = [](double width) {
      riner::Array a({64, 64});
      for (std::size_t i = 0; i < 64; ++i) {
        for (std::size_t k = 0; k < 64; ++k) {
          const double r = std::hypot(i - 31.5, k - 31.5);
          a(i, k) = static_cast<float>(std::clamp((20.0 - r) / width + 0.5, 0.0, 1.0));
        }
      }
      return a;
    };
    const riner::Array reference = disc(1.0);
    CHECK(riner::compare_images(reference, reference).edge_ratio == doctest::Approx(1.0));
    // Gaussian of 1 px on a step: 0.40 at the edge; a 6-px ramp: 1/6 over the edge pixels.
    const double soft = riner::compare_images(disc(6.0), reference).edge_ratio;
    CHECK(soft > 0.35);
    CHECK(soft < 0.7);
    // Of a volume, per axial slice: eight slices of each, the same ratio.
    riner::Array volume({8, 64, 64}), reference_volume({8, 64, 64});
    const riner::Array soft_disc = disc(6.0);
    for (std::size_t z = 0; z < 8; ++z) {
      std::copy(soft_disc.data.begin(), soft_disc.data.end(), volume.data.begin() + z * 4096);
      std::copy(reference.data.begin(), reference.data.end(),
                reference_volume.data.begin() + z * 4096);
    }
    CHECK(riner::compare_images(volume, reference_volume).edge_ratio ==
          doctest::Approx(soft).epsilon(1e-9));
  }

  TEST_CASE("masks restrict every metric") {
    riner::Array ref({20, 20}, 1.0f);
    riner::Array img = ref;
    img(0, 0) = 100.0f;  // a corner pixel, outside the inscribed circle
    const riner::Array mask = riner::circle_mask(ref.shape);
    CHECK(mask(0, 0) == 0.0f);
    CHECK(mask(10, 10) == 1.0f);
    const riner::ImageMetrics inside = riner::compare_images(img, ref, &mask, 1.0);
    CHECK(inside.mae == 0.0);
    const riner::ImageMetrics all = riner::compare_images(img, ref, nullptr, 1.0);
    CHECK(all.mae == doctest::Approx(99.0 / 400.0));
  }

  TEST_CASE("bad inputs are InputErrors") {
    CHECK_THROWS_AS(riner::compare_images(riner::Array({8, 8}), riner::Array({8, 9})),
                    riner::InputError);
    riner::Array nan_image({8, 8}, 0.0f);
    nan_image.data[3] = NAN;
    CHECK_THROWS_AS(riner::compare_images(nan_image, riner::Array({8, 8})), riner::InputError);
    CHECK_THROWS_AS(riner::compare_images(riner::Array({4, 4}), riner::Array({4, 4})),
                    riner::InputError);
  }

  TEST_CASE("a volume of fewer slices than SSIM's window: its slices' SSIM, averaged") {
    // Before: "SSIM needs every side to be at least 7 pixels", and no PSNR or MAE either.
    riner::Array a({3, 16, 16}), b({3, 16, 16});
    for (std::size_t i = 0; i < a.size(); ++i) {
      a.data[i] = static_cast<float>(std::sin(0.37 * static_cast<double>(i)));
      b.data[i] = a.data[i] + static_cast<float>(0.1 * std::cos(1.3 * static_cast<double>(i)));
    }
    const riner::ImageMetrics whole = riner::compare_images(a, b, nullptr, 2.0);
    double sum = 0.0;
    for (std::size_t k = 0; k < 3; ++k) {
      const auto slice = [&](const riner::Array& v) {
        return riner::Array(
            {16, 16}, std::vector<float>(v.data.begin() + k * 256, v.data.begin() + (k + 1) * 256));
      };
      sum += riner::compare_images(slice(a), slice(b), nullptr, 2.0).ssim;
    }
    CHECK(whole.ssim == doctest::Approx(sum / 3.0));
    CHECK(std::isfinite(whole.psnr));
  }

  TEST_CASE("ring index: high for concentric rings, low for a smooth object") {
    riner::Array smooth({64, 64});
    riner::Array ringed({64, 64});
    for (std::size_t i = 0; i < 64; ++i) {
      for (std::size_t k = 0; k < 64; ++k) {
        const double x = static_cast<double>(k) - 40.0;  // off-centre: not rotationally symmetric
        const double y = static_cast<double>(i) - 30.0;
        smooth(i, k) = static_cast<float>(std::exp(-(x * x + y * y) / 300.0));
        const double r = std::hypot(static_cast<double>(i) - 31.5, static_cast<double>(k) - 31.5);
        ringed(i, k) = smooth(i, k) + 0.2f * static_cast<float>(std::lround(r) % 2);
      }
    }
    const double clean = riner::ring_index(smooth);
    const double rings = riner::ring_index(ringed);
    MESSAGE("ring index: smooth " << clean << ", ringed " << rings);
    CHECK(clean < 0.01);
    CHECK(rings > 0.05);
    CHECK_THROWS_AS(riner::ring_index(riner::Array({4, 4, 4})), riner::InputError);
    // A volume: every slice's radii count, over the volume's range. Three copies of the ringed
    // slice read as that slice; with a smooth slice among them, lower.
    riner::Array stack({3, 64, 64});
    for (std::size_t z = 0; z < 3; ++z) {
      std::copy(ringed.data.begin(), ringed.data.end(), stack.data.begin() + z * 4096);
    }
    CHECK(riner::ring_index(stack) == doctest::Approx(rings).epsilon(1e-6));
    std::copy(smooth.data.begin(), smooth.data.end(), stack.data.begin() + 4096);
    CHECK(riner::ring_index(stack) < 0.9 * rings);
    CHECK(riner::ring_index(stack) > 0.5 * rings);
  }
}
