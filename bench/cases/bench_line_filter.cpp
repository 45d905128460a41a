// The line filter (FBP's ramp filter, the stripe filters' Fourier filters) by each of its paths
// at a detector's widths: the FFT in local memory (where a padded line fits: up to 2048 on a
// GPU's 48 KiB), the FFT in global memory (longer lines) and the direct convolution (n^2 a line,
// what longer lines took before the global FFT). --lines rows of --columns values each (a
// sinogram's views), each path on the same input, its result against the first path's.
//
//   riner_bench --case=line_filter [--columns=1024,2560,4096] [--lines=1500] [--direct=1]
#include <cmath>

#include "cl/device_access.hpp"
#include "harness.hpp"
#include "op_timer.hpp"
#include "ops/line_filter.hpp"
#include "riner/device.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;
using Path = riner::ops::LineFilterOp::Path;

const char* path_name(Path p) {
  return p == Path::kLocalFft ? "local FFT" : p == Path::kGlobalFft ? "global FFT" : "direct";
}

std::vector<Result> line_filter(const Options& o) {
  const riner::Device device = riner::Device::open(o.device, /*profiling=*/true);
  riner::cl::Context& ctx = riner::cl::context_of(device);
  const std::size_t lines = static_cast<std::size_t>(o.get_int("lines", 1500));
  const bool direct = o.get_int("direct", 1) != 0;
  std::vector<Result> results;
  for (int columns : riner::bench::int_list(o.get("columns", "1024,2560,4096"))) {
    const auto n = static_cast<std::size_t>(columns);
    std::vector<double> gain(n);
    for (std::size_t k = 0; k < n; ++k) {
      gain[k] = static_cast<double>(std::min(k, n - k)) / static_cast<double>(n);  // a ramp
    }
    riner::ops::LineFilterOp op(ctx, n, riner::ops::circular_filter_taps(gain));
    const Path chosen = op.path();
    std::vector<float> in(lines * n);
    for (std::size_t i = 0; i < in.size(); ++i) in[i] = std::sin(0.001f * static_cast<float>(i));
    const riner::cl::Buffer<float> d_in(ctx, std::span<const float>(in));
    riner::cl::Buffer<float> d_out(ctx, in.size());
    const riner::ops::LineLayout layout{lines, 0, n, 1};
    std::vector<Path> paths = {Path::kGlobalFft};
    if (chosen == Path::kLocalFft) paths.insert(paths.begin(), Path::kLocalFft);
    if (direct) paths.push_back(Path::kDirect);
    std::vector<std::vector<float>> outputs;
    for (Path p : paths) {
      op.use(p);
      const riner::bench::OpTiming t = riner::bench::time_op(device, 1, std::max(1, o.runs),
                                                             [&] { op.run(d_in, d_out, layout); });
      outputs.push_back(d_out.read());
      double worst = 0.0;
      for (std::size_t i = 0; i < in.size(); ++i) {
        worst = std::max(worst, std::fabs(static_cast<double>(outputs.back()[i] - outputs[0][i])));
      }
      results.push_back(
          {"line_filter",
           {{"columns", n},
            {"lines", lines},
            {"path", path_name(p)},
            {"chosen", p == chosen},
            {"timing", t.to_json()},
            {"max_abs_difference_to_first_path", worst}},
           riner::bench::format("%zu lines of %zu: %-10s %9.3f ms (device %9.3f ms)%s, max |diff| "
                                "%.2g",
                                lines, n, path_name(p), t.wall_ms.median, t.device_ms.median,
                                p == chosen ? " [chosen]" : "", worst)});
    }
  }
  return results;
}

}  // namespace

RINER_BENCH_CASE(line_filter, "the line filter's paths (local FFT, global FFT, direct) by width",
                 line_filter);
