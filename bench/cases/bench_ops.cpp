// Per-op micro-benchmarks: each op with warm-up and repeats, wall and per-kernel device time
// (median and quartiles), throughput in the op's own units, and GFLOP/s or GB/s as a fraction
// of the peaks measured in the same run (bench/peak.hpp).
//
// FLOP counts are the arithmetic the op must do (a multiply-add counts 2), not index or hash
// arithmetic: MLP forward 2 (inputs w + (layers - 1) w^2 + w) per sample, backward twice that
// (input and weight gradients); hash-grid forward 2^d corners x (d + 2 F) per level, backward
// 2^d x 2 F per level. Bytes are the compulsory traffic (each operand read or written once).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>

#include "cases/training_step.hpp"
#include "cl/buffer.hpp"
#include "cl/context.hpp"
#include "cl/device_access.hpp"
#include "harness.hpp"
#include "model/parameter_layout.hpp"
#include "model/ray_segments.hpp"
#include "op_timer.hpp"
#include "ops/hash_grid.hpp"
#include "ops/mlp.hpp"
#include "ops/ray_sum.hpp"
#include "peak.hpp"
#include "riner/fbp.hpp"
#include "riner/projector.hpp"
#include "riner/reconstructor.hpp"
#include "riner/simulate.hpp"
#include "scenes.hpp"

namespace {

using riner::bench::OpTiming;
using riner::bench::Options;
using riner::bench::Peaks;
using riner::bench::Result;

struct Throughput {
  double items = 0.0;  // per run, in `unit`
  std::string unit;
  double flops = 0.0;  // per run (0: not an arithmetic-bound op)
  double bytes = 0.0;  // per run (0: not counted)
};

// One row: the timing, throughput against device time (wall when the device reports none).
Result row(const std::string& op, const std::string& shape, const OpTiming& t, const Throughput& w,
           const Peaks& peaks) {
  const double ms = t.device_ms.median > 0.0 ? t.device_ms.median : t.wall_ms.median;
  nlohmann::json f = t.to_json();
  f["op"] = op;
  f["shape"] = shape;
  f["per_second"] = w.items / (ms * 1e-3);
  f["unit"] = w.unit;
  std::string rate = riner::bench::format("%9.3g %-9s", w.items / (ms * 1e-3), w.unit.c_str());
  std::string work;
  if (w.flops > 0.0) {
    const double gflops = w.flops / (ms * 1e6);
    f["gflops"] = gflops;
    f["fraction_of_device_gemm_peak"] = gflops / peaks.device_gemm_gflops;
    f["fraction_of_host_gemm_peak"] = gflops / peaks.host_gemm_gflops;
    work = riner::bench::format("%7.1f GFLOP/s (%4.1f%% dev GEMM, %4.1f%% host GEMM)", gflops,
                                100.0 * gflops / peaks.device_gemm_gflops,
                                100.0 * gflops / peaks.host_gemm_gflops);
  } else if (w.bytes > 0.0) {
    const double gbps = w.bytes / (ms * 1e6);
    f["gbps"] = gbps;
    f["fraction_of_bandwidth"] = gbps / peaks.device_gbps;
    work = riner::bench::format("%7.1f GB/s    (%4.1f%% of streaming)", gbps,
                                100.0 * gbps / peaks.device_gbps);
  }
  return {"ops", f,
          riner::bench::format("%-24s %-22s %9.3f ms [%7.3f..%7.3f] %9.3f ms dev  %s %s",
                               op.c_str(), shape.c_str(), t.wall_ms.median, t.wall_ms.q25,
                               t.wall_ms.q75, t.device_ms.median, rate.c_str(), work.c_str())};
}

std::vector<float> uniform(std::size_t n, float lo, float hi, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> d(lo, hi);
  std::vector<float> v(n);
  for (float& x : v) x = d(rng);
  return v;
}

double mlp_forward_flops(const riner::model::ParameterLayout& l) {
  return 2.0 * (l.inputs * l.width + (l.hidden_layers - 1) * l.width * l.width + l.width);
}

double grid_forward_flops(const riner::model::ParameterLayout& l) {
  return l.levels * std::pow(2.0, l.dims) * (l.dims + 2.0 * l.features);
}

double grid_backward_flops(const riner::model::ParameterLayout& l) {
  return l.levels * std::pow(2.0, l.dims) * 2.0 * l.features;
}

// The default model's layout with `width` (the 512^2 paper grid's finest level, 768 elements).
riner::model::ParameterLayout bench_layout(int width) {
  riner::RinerConfig config;
  config.encoding.finest_resolution = 512;  // what auto picks on the 512^2 paper grid
  config.network.width = width;
  return riner::model::make_layout(2, config.encoding, config.network, 768);
}

std::size_t bench_samples(const Options& o) {
  return o.size == "tiny" ? 4096 : (std::size_t{1} << 17);
}

// kernels/hash_grid.cl (ops::HashGridOp) on n samples.
void hash_grid_ops(const riner::Device& device, const Options& o, const Peaks& peaks,
                   std::vector<Result>* out) {
  riner::cl::Context& ctx = riner::cl::context_of(device);
  const std::size_t n = bench_samples(o);
  const riner::model::ParameterLayout l = bench_layout(16);
  riner::cl::Buffer<float> params(ctx,
                                  std::span<const float>(riner::model::initial_parameters(l, 1)));
  riner::cl::Buffer<float> grad(ctx, std::vector<float>(l.total, 0.0f));
  riner::cl::Buffer<float> positions(ctx, std::span<const float>(uniform(2 * n, 0.0f, 1.0f, 2)));
  riner::cl::Buffer<float> features(ctx, n * l.inputs);
  riner::cl::Buffer<float> d_features(
      ctx, std::span<const float>(uniform(n * l.inputs, -1.0f, 1.0f, 3)));
  riner::ops::HashGridOp grid(ctx, l);
  const double lookups = static_cast<double>(n) * l.levels * 4;
  OpTiming t = riner::bench::time_op(device, o.warmup, o.runs,
                                     [&] { grid.forward(params, positions, features); });
  out->push_back(row("hash_grid_forward", std::to_string(n) + " pts, L=8 F=2", t,
                     {lookups, "lookups/s", n * grid_forward_flops(l), 0.0}, peaks));
  t = riner::bench::time_op(device, o.warmup, o.runs,
                            [&] { grid.backward(positions, d_features, grad); });
  out->push_back(row("hash_grid_backward", std::to_string(n) + " pts, L=8 F=2", t,
                     {lookups, "lookups/s", n * grid_backward_flops(l), 0.0}, peaks));
}

// kernels/mlp.cl (ops::MlpOp) on n samples, widths 16 and 64, and its first layer as one
// CLBlast SGEMM: the library path issue 4 weighed against the fused kernels (activations go
// through global memory).
void mlp_ops(const riner::Device& device, const Options& o, const Peaks& peaks,
             std::vector<Result>* out) {
  riner::cl::Context& ctx = riner::cl::context_of(device);
  const std::size_t n = bench_samples(o);
  for (int width : {16, 64}) {
    const riner::model::ParameterLayout l = bench_layout(width);
    riner::cl::Buffer<float> params(ctx,
                                    std::span<const float>(riner::model::initial_parameters(l, 1)));
    riner::cl::Buffer<float> grad(ctx, std::vector<float>(l.total, 0.0f));
    riner::cl::Buffer<float> features(
        ctx, std::span<const float>(uniform(n * l.inputs, -1.0f, 1.0f, 3)));
    riner::cl::Buffer<float> mu(ctx, n);
    riner::cl::Buffer<float> d_mu(ctx, std::span<const float>(uniform(n, -1.0f, 1.0f, 4)));
    riner::cl::Buffer<float> d_inputs(ctx, n * l.inputs);
    const std::string shape =
        std::to_string(n) + " x " + std::to_string(l.inputs) + " -> " + std::to_string(width);
    riner::ops::MlpOp mlp(ctx, l);
    OpTiming t =
        riner::bench::time_op(device, o.warmup, o.runs, [&] { mlp.forward(params, features, mu); });
    out->push_back(row("mlp_forward_batch", shape, t,
                       {static_cast<double>(n), "samples/s", n * mlp_forward_flops(l), 0.0},
                       peaks));
    t = riner::bench::time_op(device, o.warmup, o.runs,
                              [&] { mlp.backward(params, features, d_mu, grad, d_inputs); });
    out->push_back(row("mlp_backward_batch", shape, t,
                       {static_cast<double>(n), "samples/s", 2.0 * n * mlp_forward_flops(l), 0.0},
                       peaks));
    const double gemm_ms =
        riner::bench::clblast_gemm_ms(device, n, static_cast<std::size_t>(width),
                                      static_cast<std::size_t>(l.inputs), o.warmup, o.runs);
    OpTiming gemm;
    gemm.wall_ms.median = gemm.wall_ms.q25 = gemm.wall_ms.q75 = gemm_ms;
    out->push_back(row("clblast_first_layer", shape, gemm,
                       {static_cast<double>(n), "samples/s", 2.0 * n * l.inputs * width, 0.0},
                       peaks));
  }
}

// The first layer's weight gradient (inputs x width, summed over a step's samples) as one
// CLBlast SGEMM, to weigh against mlp_gradient.cl's split-K kernels (their time is in the
// training_step rows: the whole MLP's gradient, mlp_gradient_*). Samples per step of the
// default plans: 11k (160 rays), 45k (640), 180k (2560).
void mlp_gradient_ops(const riner::Device& device, const Options& o, const Peaks& peaks,
                      std::vector<Result>* out) {
  for (const std::size_t samples : o.size == "tiny"
                                       ? std::vector<std::size_t>{4096}
                                       : std::vector<std::size_t>{11264, 45056, 180224}) {
    const riner::model::ParameterLayout l = bench_layout(32);
    const double ms = riner::bench::clblast_gemm_ms(device, static_cast<std::size_t>(l.inputs), 32,
                                                    samples, o.warmup, o.runs);
    OpTiming gemm;
    gemm.wall_ms.median = gemm.wall_ms.q25 = gemm.wall_ms.q75 = ms;
    out->push_back(row(
        "clblast_weight_gradient", std::to_string(l.inputs) + " x 32, K=" + std::to_string(samples),
        gemm, {static_cast<double>(samples), "samples/s", 2.0 * samples * l.inputs * 32, 0.0},
        peaks));
  }
}

// kernels/ray_sum.cl (ops::RaySumOp), the forward model and loss on explicit samples: 4096 rays
// of 128 samples (the unfused path).
void ray_sum_ops(const riner::Device& device, const Options& o, const Peaks& peaks,
                 std::vector<Result>* out) {
  riner::cl::Context& ctx = riner::cl::context_of(device);
  const std::size_t rays = o.size == "tiny" ? 256 : 4096, per_ray = 128;
  std::vector<cl_uint> offsets(rays + 1);
  for (std::size_t r = 0; r <= rays; ++r) offsets[r] = static_cast<cl_uint>(r * per_ray);
  std::vector<cl_uint> elements(rays);
  for (std::size_t r = 0; r < rays; ++r) elements[r] = static_cast<cl_uint>(r % 768);
  riner::cl::Buffer<cl_uint> offsets_b(ctx, std::span<const cl_uint>(offsets));
  riner::cl::Buffer<cl_uint> elements_b(ctx, std::span<const cl_uint>(elements));
  riner::cl::Buffer<float> dx(ctx, std::vector<float>(rays, 0.5f));
  riner::cl::Buffer<float> rho(ctx, std::span<const float>(uniform(rays, 0.0f, 3.0f, 5)));
  riner::cl::Buffer<float> mu(ctx, std::span<const float>(uniform(rays * per_ray, 0.0f, 0.03f, 6)));
  riner::cl::Buffer<float> d_mu(ctx, rays * per_ray);
  riner::cl::Buffer<float> loss(ctx, rays);
  riner::cl::Buffer<float> alpha0(ctx, std::vector<float>(768, 1.0f));
  riner::cl::Buffer<float> beta0(ctx, std::vector<float>(768, 1.0f));
  riner::cl::Buffer<float> d_alpha0(ctx, std::vector<float>(768, 0.0f));
  riner::cl::Buffer<float> d_beta0(ctx, std::vector<float>(768, 0.0f));
  riner::ops::RaySumOp ray_sum(ctx);
  const riner::ops::RaySumOp::Rays r{&offsets_b, &dx, &elements_b, &rho};
  const OpTiming t = riner::bench::time_op(device, o.warmup, o.runs, [&] {
    ray_sum.loss(r, mu, alpha0, beta0, 1.0f, 0.0f, d_mu, loss, d_alpha0, d_beta0);
  });
  out->push_back(row("ray_sum_loss", std::to_string(rays) + " rays x 128", t,
                     {static_cast<double>(rays), "rays/s", 0.0,
                      2.0 * sizeof(float) * rays * per_ray + 4.0 * sizeof(float) * rays},
                     peaks));
}

// The trained field evaluated on the paper's 512^2 grid.
void field_image(const riner::Device& device, const Options& o, const Peaks& peaks,
                 std::vector<Result>* out) {
  const riner::Projector projector(riner::preset_geometry("fan2d-paper"), riner::Engine::kOpenCL,
                                   device);
  const riner::bench::RingScene scene = riner::bench::paper_scene(o, 0, projector);
  riner::RinerConfig config = riner::bench::config_from(o);
  config.training.skip_air = false;  // the whole grid
  riner::Reconstructor r(scene.sim.scan, config, device);
  r.step(1);
  const riner::model::ParameterLayout l =
      riner::model::make_layout(2, config.encoding, config.network, scene.sim.scan.geometry.n_u);
  const OpTiming e =
      riner::bench::time_op(device, 1, o.size == "tiny" ? 1 : 5, [&] { r.field_image(); });
  const double pixels = 512.0 * 512.0;
  out->push_back(row(
      "riner_step_field_evaluate", "512 x 512", e,
      {pixels, "pixels/s", pixels * (grid_forward_flops(l) + mlp_forward_flops(l)), 0.0}, peaks));
}

// Geometry-side ops: ray clipping on the host, projector, adjoint and FBP on the device.
void geometry_ops(const riner::Device& device, const Options& o, const Peaks& peaks,
                  std::vector<Result>* out) {
  const riner::Geometry g = riner::preset_geometry("fan2d-paper");
  const double rays = static_cast<double>(g.n_views() * g.n_u);
  const int runs = o.size == "tiny" ? 1 : std::max(3, o.runs / 2);
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i)
    ms.push_back(riner::bench::time_ms([&] { riner::model::ray_segments(g, g.voxel_mm, false); }));
  OpTiming host;
  host.wall_ms = riner::bench::Stats::of(ms);
  out->push_back(
      row("ray_segments (host)", "fan2d-paper", host, {rays, "rays/s", 0.0, 0.0}, peaks));

  const riner::Projector projector(g, riner::Engine::kOpenCL, device);
  const riner::Array image(g.volume_shape, 0.01f);
  const riner::Array sinogram(std::vector<std::size_t>{g.n_views(), g.n_u}, 1.0f);
  OpTiming t = riner::bench::time_op(device, 1, runs, [&] { projector.project(image); });
  out->push_back(
      row("project (Joseph)", "512^2 -> 1000 x 768", t, {rays, "rays/s", 0.0, 0.0}, peaks));
  t = riner::bench::time_op(device, 1, runs, [&] { projector.adjoint(sinogram); });
  out->push_back(
      row("backproject (adjoint)", "1000 x 768 -> 512^2", t, {rays, "rays/s", 0.0, 0.0}, peaks));
  riner::FbpOptions fbp_options;
  fbp_options.device = device;
  const riner::Scan scan{sinogram, g, 0};
  t = riner::bench::time_op(device, 1, runs, [&] { riner::fbp(scan, fbp_options); });
  out->push_back(
      row("fbp (Ram-Lak)", "1000 x 768 -> 512^2", t, {1.0, "images/s", 0.0, 0.0}, peaks));
}

std::vector<Result> peak(const Options& o) {
  const riner::Device device = riner::Device::open(o.device, true);
  const Peaks p = riner::bench::measure_peaks(device, o);
  nlohmann::json f = p.details;
  f.update({{"host_gemm_gflops", p.host_gemm_gflops},
            {"device_gemm_gflops", p.device_gemm_gflops},
            {"device_gbps", p.device_gbps}});
  return {{"peak", f,
           riner::bench::format("peak: host GEMM %.1f GFLOP/s, device GEMM %.1f GFLOP/s, device "
                                "streaming %.1f GB/s",
                                p.host_gemm_gflops, p.device_gemm_gflops, p.device_gbps)}};
}

std::vector<Result> ops(const Options& o) {
  const riner::Device device = riner::Device::open(o.device, true);
  std::vector<Result> out = peak(o);
  const nlohmann::json& f = out.front().fields;
  const Peaks peaks{f["host_gemm_gflops"], f["device_gemm_gflops"], f["device_gbps"], {}};
  out.front().line += riner::bench::format("\n%-24s %-22s %9s    [%7s..%7s] %9s", "op", "shape",
                                           "wall", "q25", "q75", "device");
  hash_grid_ops(device, o, peaks, &out);
  mlp_ops(device, o, peaks, &out);
  mlp_gradient_ops(device, o, peaks, &out);
  ray_sum_ops(device, o, peaks, &out);
  // The training step under the device's own plan, then the other one (both run everywhere).
  for (Result& r : riner::bench::time_training_steps(
           device, o, {"", device.info().type == "CPU" ? "gpu" : "cpu"}, {0}, &peaks))
    out.push_back(std::move(r));
  // The field on the 512^2 grid (chunked riner_step_field_evaluate).
  field_image(device, o, peaks, &out);
  geometry_ops(device, o, peaks, &out);
  return out;
}

}  // namespace

RINER_BENCH_CASE(peak, "measured peaks: host GEMM (Eigen), device GEMM (CLBlast), bandwidth", peak);
RINER_BENCH_CASE(ops, "per-op micro-benchmarks against the measured peaks", ops);
