#include "peak.hpp"

#include <clblast.h>
#include <Eigen/Dense>

#include <stdexcept>
#include <thread>
#include <vector>

#include "cl/buffer.hpp"
#include "cl/context.hpp"
#include "cl/device_access.hpp"
#include "op_timer.hpp"
#include "ops/vector_ops.hpp"

namespace riner::bench {

namespace {

double host_gemm_gflops(std::size_t n, int runs) {
  const Eigen::MatrixXf a = Eigen::MatrixXf::Random(n, n);
  const Eigen::MatrixXf b = Eigen::MatrixXf::Random(n, n);
  Eigen::MatrixXf c(n, n);
  // Eigen runs single-threaded without OpenMP: give each core its own block of columns.
  const std::size_t threads = std::max(1u, std::thread::hardware_concurrency());
  auto product = [&] {
    std::vector<std::thread> pool;
    const std::size_t block = (n + threads - 1) / threads;
    for (std::size_t t = 0; t < threads; ++t) {
      const std::size_t first = t * block;
      if (first >= n) break;
      const std::size_t cols = std::min(block, n - first);
      pool.emplace_back([&, first, cols] {
        c.middleCols(first, cols).noalias() = a * b.middleCols(first, cols);
      });
    }
    for (std::thread& th : pool) th.join();
  };
  product();
  std::vector<double> ms;
  for (int i = 0; i < runs; ++i) ms.push_back(time_ms(product));
  return 2.0 * n * n * n / (Stats::of(ms).median * 1e6);
}

}  // namespace

double clblast_gemm_ms(const Device& device, std::size_t m, std::size_t n, std::size_t k,
                       int warmup, int runs) {
  cl::Context& ctx = riner::cl::context_of(device);
  cl::Buffer<float> a(ctx, std::vector<float>(m * k, 0.5f));
  cl::Buffer<float> b(ctx, std::vector<float>(k * n, 0.25f));
  cl::Buffer<float> c(ctx, m * n);
  cl_command_queue queue = ctx.queue();
  auto gemm = [&] {
    const clblast::StatusCode status = clblast::Gemm<float>(
        clblast::Layout::kRowMajor, clblast::Transpose::kNo, clblast::Transpose::kNo, m, n, k, 1.0f,
        a.get(), 0, k, b.get(), 0, n, 0.0f, c.get(), 0, n, &queue);
    if (status != clblast::StatusCode::kSuccess)
      throw std::runtime_error("CLBlast SGEMM failed with status " +
                               std::to_string(static_cast<int>(status)));
  };
  const double ms = time_op(device, warmup, runs, gemm).wall_ms.median;
  // CLBlast keeps its programs in a process-wide cache that would otherwise outlive the
  // context and be released during exit, after the OpenCL runtime is gone.
  clblast::ClearCache();
  return ms;
}

Peaks measure_peaks(const Device& device, const Options& o) {
  const bool tiny = o.size == "tiny";
  const std::size_t n = static_cast<std::size_t>(o.get_int("gemm_n", tiny ? 512 : 2048));
  const int runs = tiny ? 1 : 5;
  Peaks p;
  p.host_gemm_gflops = host_gemm_gflops(n, runs);
  p.device_gemm_gflops = 2.0 * n * n * n / (clblast_gemm_ms(device, n, n, n, 1, runs) * 1e6);

  cl::Context& ctx = riner::cl::context_of(device);
  const std::size_t count = tiny ? (std::size_t{1} << 20) : (std::size_t{1} << 25);
  cl::Buffer<float> x(ctx, count);
  cl::Buffer<float> y(ctx, count);
  ops::VectorOps vec(ctx);
  vec.fill(x, 1.0f);
  vec.fill(y, 0.0f);
  const OpTiming t = time_op(device, 1, runs, [&] { vec.axpy(0.5f, x, y); });
  const double bytes = 3.0 * sizeof(float) * count;  // read x and y, write y
  p.device_gbps = bytes / (t.wall_ms.median * 1e6);
  p.details = {{"gemm_n", n},
               {"host_gemm", "Eigen " + std::to_string(EIGEN_WORLD_VERSION) + "." +
                                 std::to_string(EIGEN_MAJOR_VERSION) + "." +
                                 std::to_string(EIGEN_MINOR_VERSION) + ", " +
                                 std::to_string(std::thread::hardware_concurrency()) + " threads"},
               {"device_gemm", "CLBlast SGEMM"},
               {"bandwidth_floats", count}};
  return p;
}

}  // namespace riner::bench
