// Every classical stripe-removal method on the device (lib/src/destripe/device_destripe.cpp:
// kernels/stripe_sorting.cl, stripe_columns.cl, line_filter.cl, wavelet.cl) against its CPU
// twin (destripe.cpp, sinogram_ops.cpp, wavelets.cpp): the same readings, the same dead and
// large stripes found, at view counts that are not powers of two, ties, and windows from 1 to
// the sorting kernel's widest.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>
#include <string>

#include "cl/buffer.hpp"
#include "cl/device_access.hpp"
#include "ops/line_filter.hpp"
#include "ops/stripe_sorting.hpp"
#include "riner/destripe.hpp"
#include "support/compare.hpp"
#include "support/fixture.hpp"
#include "support/geometries.hpp"

namespace {

constexpr riner::DestripeMethod kMethods[] = {
    riner::DestripeMethod::kNormalise, riner::DestripeMethod::kSorting,
    riner::DestripeMethod::kFiltering, riner::DestripeMethod::kFitting,
    riner::DestripeMethod::kWavelet,   riner::DestripeMethod::kLarge,
    riner::DestripeMethod::kDead,      riner::DestripeMethod::kAll};

// A smooth sinogram with noise, an offset on every seventh column, a large stripe (columns 10-12
// raised by 0.8) and a dead column (23, constant): something for every method to find.
riner::Array sinogram(std::size_t views, std::size_t columns, bool ties, std::uint32_t seed,
                      bool dead_column = true) {
  riner::Array a({views, columns});
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.0f, 0.05f);
  for (std::size_t v = 0; v < views; ++v) {
    for (std::size_t c = 0; c < columns; ++c) {
      float x = 0.5f + 0.3f * std::sin(0.05f * static_cast<float>(c) + 0.02f * static_cast<float>(v)) +
                noise(rng) + 0.02f * static_cast<float>(c % 7);
      if (c >= 10 && c <= 12 && columns > 40) x += 0.8f;
      if (c == 23 && columns > 40 && dead_column) x = 0.6f;
      if (ties) x = std::round(x * 20.0f) / 20.0f;  // many equal readings in a column
      a.data[v * columns + c] = x;
    }
  }
  return a;
}

void check_method(riner::DestripeMethod method, std::size_t views, std::size_t columns,
                  std::size_t size, bool ties) {
  const std::string name = riner::destripe_method_name(method);
  CAPTURE(name);
  CAPTURE(views);
  CAPTURE(columns);
  CAPTURE(size);
  CAPTURE(ties);
  const riner::Geometry g = riner::test::make_geometry(riner::GeometryType::kParallel2d, views,
                                                       columns, 1, {32, 32}, 1.0, 1.0, M_PI);
  // Sorting ranks readings that a filter or an interpolation computed before it (filtering's
  // low-pass, all's dead columns) where rounding alone tells near-equal ones apart: a constant
  // column low-passed, or tied readings interpolated, rank in an order float and double
  // decide differently, and both are right. Those methods get no such readings here; the
  // sorting method itself is checked on ties and a constant column, to the bit.
  const bool ranks_computed = method == riner::DestripeMethod::kFiltering ||
                              method == riner::DestripeMethod::kAll;
  const riner::Array in = sinogram(views, columns, ties && !ranks_computed, 11,
                                   method != riner::DestripeMethod::kFiltering);
  riner::DestripeOptions options;
  options.method = method;
  options.size = size;
  options.engine = riner::Engine::kReference;
  riner::DestripeReport cpu, device;
  const riner::Array reference = riner::destripe(in, g, options, &cpu);
  options.engine = riner::Engine::kOpenCL;
  options.device = riner::test::device();
  const riner::Array on_device = riner::destripe(in, g, options, &device);
  REQUIRE(on_device.data.size() == reference.data.size());
  const riner::test::ErrorStats d = riner::test::compare(on_device.data, reference.data);
  CHECK(d.non_finite == 0);
  CHECK(device.dead == cpu.dead);
  CHECK(device.large == cpu.large);
  // float on the device, double on the CPU, on readings of about 1: a few float epsilons
  // through each sum (the sorting step's mean along the ranks too), FFT or wavelet level.
  CHECK(d.max_abs < 2e-5);
  if (method == riner::DestripeMethod::kSorting) {
    // Without the mean along the ranks, the same readings picked and put back in the same views.
    options.rank_window = 1;
    const riner::Array picked = riner::destripe(in, g, options);
    options.engine = riner::Engine::kReference;
    const riner::Array picked_on_cpu = riner::destripe(in, g, options);
    CHECK(riner::test::compare(picked.data, picked_on_cpu.data).max_abs == 0.0);
  }
  REQUIRE(device.removed.data.size() == cpu.removed.data.size());
  CHECK(riner::test::compare(device.removed.data, cpu.removed.data).max_abs < 2e-5);
}

}  // namespace

TEST_SUITE("destripe_device") {
  TEST_CASE("every method on the device equals its CPU twin, ties and odd sizes included") {
    struct Case {
      std::size_t views, columns, size;
      bool ties;
    };
    for (const Case k : {Case{181, 97, 21, false}, Case{181, 97, 21, true}, Case{64, 40, 1, false},
                         Case{33, 300, 255, true}, Case{360, 64, 5, true}}) {
      for (riner::DestripeMethod method : kMethods) check_method(method, k.views, k.columns, k.size, k.ties);
    }
  }

  TEST_CASE("the stripes each method finds are found on the device too") {
    // The sinogram's large stripe and dead column must be found for this check to mean anything.
    const riner::Geometry g = riner::test::make_geometry(riner::GeometryType::kParallel2d, 120, 90,
                                                         1, {32, 32}, 1.0, 1.0, M_PI);
    riner::DestripeOptions options;
    options.method = riner::DestripeMethod::kAll;
    options.device = riner::test::device();
    riner::DestripeReport report;
    (void)riner::destripe(sinogram(120, 90, false, 5), g, options, &report);
    CHECK(std::find(report.dead.begin(), report.dead.end(), std::size_t{23}) != report.dead.end());
    CHECK(std::find(report.large.begin(), report.large.end(), std::size_t{11}) != report.large.end());
  }

  TEST_CASE("the line filter on strided lines (columns of a block), by FFT and directly") {
    // A GPU with little local memory takes the direct path for long lines (many views): both
    // paths on the layouts the stripe filters use, against the circular convolution in double.
    riner::cl::Context& ctx = riner::cl::context_of(riner::test::device());
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> value(-1.0f, 2.0f);
    const std::size_t rows = 37, width = 23;  // the array; lines are a block's columns
    std::vector<float> in(rows * width);
    for (float& v : in) v = value(rng);
    struct Layout {
      std::size_t n, lines, first, line_step, stride;
    };
    for (const Layout l : {Layout{37, 23, 0, 1, 23}, Layout{16, 9, 5 * 23 + 3, 1, 23},
                           Layout{23, 37, 0, 23, 1}, Layout{10, 4, 2 * 23 + 11, 23, 1}}) {
      CAPTURE(l.n);
      CAPTURE(l.first);
      CAPTURE(l.stride);
      std::vector<double> gain(l.n);
      for (std::size_t k = 0; k < l.n; ++k) {
        const double f = static_cast<double>(std::min(k, l.n - k));
        gain[k] = 1.0 - std::exp(-0.5 * f * f / 4.0);
      }
      const std::vector<double> taps = riner::ops::circular_filter_taps(gain);
      // The circular convolution out[i] = sum_j in[j] h[(i - j) mod n], h = taps[d + n - 1].
      std::vector<float> expected = in;
      for (std::size_t line = 0; line < l.lines; ++line) {
        const std::size_t start = l.first + line * l.line_step;
        for (std::size_t i = 0; i < l.n; ++i) {
          double sum = 0.0;
          for (std::size_t j = 0; j < l.n; ++j) {
            sum += taps[i - j + l.n - 1] * in[start + j * l.stride];
          }
          expected[start + i * l.stride] = static_cast<float>(sum);
        }
      }
      riner::ops::LineFilterOp op(ctx, l.n, taps);
      CHECK(op.by_fft());  // PoCL's local memory holds these lines
      using Path = riner::ops::LineFilterOp::Path;
      // The global FFT on 2 work-groups: each filters every second pair of lines.
      for (Path path : {Path::kLocalFft, Path::kGlobalFft, Path::kDirect}) {
        CAPTURE(static_cast<int>(path));
        op.use(path, 2);
        const riner::cl::Buffer<float> d_in(ctx, std::span<const float>(in));
        riner::cl::Buffer<float> d_out(ctx, std::span<const float>(in));  // outside the lines: kept
        op.run(d_in, d_out, riner::ops::LineLayout{l.lines, l.first, l.line_step, l.stride});
        const riner::test::ErrorStats stats = riner::test::compare(d_out.read(), expected);
        CHECK(stats.non_finite == 0);
        CHECK(stats.max_abs < 2e-5);
      }
    }
  }

  TEST_CASE("the sorting step's GPU and CPU shapes agree to the bit") {
    // The CPU device runs the CPU's shape in every test above; here the bitonic sort and the
    // quickselect, on ties, -0 beside +0, a constant column, and windows wider than the row.
    riner::cl::Context& ctx = riner::cl::context_of(riner::test::device());
    using Shape = riner::ops::StripeSortingOp::Shape;
    struct Case {
      std::size_t views, columns, size;
    };
    for (const Case k : {Case{45, 31, 21}, Case{2, 9, 3}, Case{37, 40, 255}, Case{30, 80, 51},
                         Case{64, 33, 1}}) {
      CAPTURE(k.views);
      CAPTURE(k.columns);
      CAPTURE(k.size);
      std::mt19937 rng(static_cast<std::uint32_t>(k.views * 1000 + k.size));
      std::uniform_int_distribution<int> level(-6, 6);
      std::vector<float> in(k.views * k.columns);
      for (std::size_t i = 0; i < in.size(); ++i) {
        const std::size_t c = i % k.columns;
        in[i] = c == 3 ? 0.25f : static_cast<float>(level(rng)) / 8.0f;  // many ties
        if (in[i] == 0.0f && i % 2 == 1) in[i] = -0.0f;
      }
      const riner::cl::Buffer<float> d_in(ctx, std::span<const float>(in));
      std::vector<std::vector<float>> sorted, filtered, out;
      for (Shape shape : {Shape::kBitonic, Shape::kSerial}) {
        riner::ops::StripeSortingOp op(ctx, k.views, k.columns);
        op.use_shape(shape);
        op.sort(d_in);
        op.median(k.size);
        riner::cl::Buffer<float> d_out(ctx, k.views * k.columns);
        op.unsort(d_out);
        sorted.push_back(op.sorted().read());
        filtered.push_back(op.filtered().read());
        out.push_back(d_out.read());
      }
      // Ranked by (value, view) in both: the same bits, the views' order kept among equals.
      CHECK(std::memcmp(sorted[0].data(), sorted[1].data(), sorted[0].size() * sizeof(float)) == 0);
      CHECK(filtered[0] == filtered[1]);
      CHECK(out[0] == out[1]);
      bool ranked = true;
      for (std::size_t r = 1; r < k.views; ++r) {
        for (std::size_t c = 0; c < k.columns; ++c) {
          ranked = ranked && sorted[1][(r - 1) * k.columns + c] <= sorted[1][r * k.columns + c];
        }
      }
      CHECK(ranked);
    }
  }

  TEST_CASE("every method on a tiny sinogram (the oclgrind tier)") {
    for (riner::DestripeMethod method : kMethods) check_method(method, 24, 20, 5, false);
  }
}
