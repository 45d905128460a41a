// The machine's measured peaks, the yardstick for every op's GFLOP/s and GB/s: a large GEMM on
// the host (Eigen, one block of columns per core), the device's best GEMM (CLBlast SGEMM) and
// the device's streaming bandwidth (y += a x over buffers far larger than the caches).
#pragma once

#include <nlohmann/json.hpp>

#include "harness.hpp"
#include "riner/device.hpp"

namespace riner::bench {

struct Peaks {
  double host_gemm_gflops = 0.0;
  double device_gemm_gflops = 0.0;
  double device_gbps = 0.0;
  nlohmann::json details;  // sizes and per-size results
};

// n: square GEMM size (2048 for small and up, 512 for tiny).
Peaks measure_peaks(const Device& device, const Options& o);

// Single-precision GEMM C = A B (m x k times k x n, row major) by CLBlast on the device;
// median milliseconds over `runs`.
double clblast_gemm_ms(const Device& device, std::size_t m, std::size_t n, std::size_t k,
                       int warmup, int runs);

}  // namespace riner::bench
