// Vo's sorting step on the device (kernels/stripe_sorting.cl) against its CPU twin
// (lib/src/destripe/sinogram_ops.cpp): the same values in the same places, ties included,
// at view counts that are not powers of two and windows from 1 to the kernel's widest.
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "riner/destripe.hpp"
#include "support/fixture.hpp"
#include "support/geometries.hpp"

namespace {

riner::Array sinogram(std::size_t views, std::size_t columns, bool ties, std::uint32_t seed) {
  riner::Array a({views, columns});
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  for (std::size_t v = 0; v < views; ++v) {
    for (std::size_t c = 0; c < columns; ++c) {
      float x = 0.5f + 0.3f * std::sin(0.05f * static_cast<float>(c) + 0.02f * static_cast<float>(v)) +
                noise(rng) + 0.02f * static_cast<float>(c % 7);
      if (ties) x = std::round(x * 20.0f) / 20.0f;  // many equal readings in a column
      a.data[v * columns + c] = x;
    }
  }
  return a;
}

}  // namespace

TEST_SUITE("stripe_sorting") {
  TEST_CASE("the device's sorting step equals the CPU twin's, ties and odd sizes included") {
    struct Case {
      std::size_t views, columns, size;
      bool ties;
    };
    for (const Case k : {Case{181, 97, 21, false}, Case{181, 97, 21, true}, Case{64, 40, 1, false},
                         Case{33, 300, 255, true}, Case{360, 64, 5, true}}) {
      CAPTURE(k.views);
      CAPTURE(k.columns);
      CAPTURE(k.size);
      CAPTURE(k.ties);
      const riner::Geometry g = riner::test::make_geometry(
          riner::GeometryType::kParallel2d, k.views, k.columns, 1, {32, 32}, 1.0, 1.0, M_PI);
      const riner::Array in = sinogram(k.views, k.columns, k.ties, 11);
      for (riner::DestripeMethod method :
           {riner::DestripeMethod::kSorting, riner::DestripeMethod::kFiltering}) {
        CAPTURE(riner::destripe_method_name(method));
        riner::DestripeOptions options;
        options.method = method;
        options.size = k.size;
        options.engine = riner::Engine::kReference;
        const riner::Array reference = riner::destripe(in, g, options);
        options.engine = riner::Engine::kOpenCL;
        options.device = riner::test::device();
        const riner::Array device = riner::destripe(in, g, options);
        REQUIRE(device.data.size() == reference.data.size());
        std::size_t differ = 0;
        float worst = 0.0f;
        for (std::size_t i = 0; i < device.data.size(); ++i) {
          const float d = std::fabs(device.data[i] - reference.data[i]);
          differ += d > 0.0f;
          worst = std::max(worst, d);
        }
        if (method == riner::DestripeMethod::kSorting) {
          CHECK(differ == 0);  // the same readings picked and put back in the same views
        } else {
          CHECK(worst < 1e-5f);  // the low-pass part arrives in double on the CPU, float here
        }
      }
    }
  }
}
