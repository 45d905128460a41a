#include "destripe/wavelets.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <complex>
#include <stdexcept>

namespace riner::stripes {

namespace {

// One periodised analysis step of a line of n (even) values `stride` apart: the n/2
// approximation coefficients, then the n/2 details, written back over the line.
void analyse_line(double* line, std::size_t n, std::size_t stride, const std::vector<double>& h,
                  const std::vector<double>& g, std::vector<double>& scratch) {
  scratch.assign(n, 0.0);
  const std::size_t half = n / 2;
  for (std::size_t k = 0; k < half; ++k) {
    double a = 0.0, d = 0.0;
    for (std::size_t t = 0; t < h.size(); ++t) {
      const double x = line[((2 * k + t) % n) * stride];
      a += h[t] * x;
      d += g[t] * x;
    }
    scratch[k] = a;
    scratch[half + k] = d;
  }
  for (std::size_t i = 0; i < n; ++i) line[i * stride] = scratch[i];
}

// The transpose of analyse_line, which is its inverse (the step is orthonormal).
void synthesise_line(double* line, std::size_t n, std::size_t stride,
                     const std::vector<double>& h, const std::vector<double>& g,
                     std::vector<double>& scratch) {
  scratch.assign(n, 0.0);
  const std::size_t half = n / 2;
  for (std::size_t k = 0; k < half; ++k) {
    const double a = line[k * stride], d = line[(half + k) * stride];
    for (std::size_t t = 0; t < h.size(); ++t) scratch[(2 * k + t) % n] += h[t] * a + g[t] * d;
  }
  for (std::size_t i = 0; i < n; ++i) line[i * stride] = scratch[i];
}

}  // namespace

std::vector<double> wavelet_high_pass(const std::vector<double>& low_pass) {
  std::vector<double> g(low_pass.size());
  for (std::size_t n = 0; n < low_pass.size(); ++n) {
    g[n] = (n % 2 == 0 ? 1.0 : -1.0) * low_pass[low_pass.size() - 1 - n];
  }
  return g;
}

std::vector<double> daubechies_filter(int order) {
  if (order < 1 || order > 12) throw std::invalid_argument("Daubechies order must be 1..12");
  const int n = order;
  // |H(w)|^2 = cos^2(w/2)^n P(sin^2(w/2)), P(y) = sum_k C(n-1+k, k) y^k: its roots y_i.
  std::vector<double> p(static_cast<std::size_t>(n));
  double binomial = 1.0;
  for (int k = 0; k < n; ++k) {
    p[static_cast<std::size_t>(k)] = binomial;  // C(n-1+k, k)
    binomial = binomial * (n + k) / (k + 1);
  }
  std::vector<std::complex<double>> zeros;
  if (n > 1) {
    const int degree = n - 1;
    Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(degree, degree);
    for (int i = 1; i < degree; ++i) companion(i, i - 1) = 1.0;
    for (int i = 0; i < degree; ++i) {
      companion(i, degree - 1) = -p[static_cast<std::size_t>(i)] / p[static_cast<std::size_t>(degree)];
    }
    const Eigen::VectorXcd y = Eigen::EigenSolver<Eigen::MatrixXd>(companion, false).eigenvalues();
    // y = (2 - z - 1/z) / 4: z and 1/z share a y; the one inside the unit circle makes the
    // filter minimum-phase.
    for (int i = 0; i < degree; ++i) {
      const std::complex<double> b = 2.0 - 4.0 * y(i);
      const std::complex<double> root = std::sqrt(b * b - 4.0);
      std::complex<double> z = 0.5 * (b + root);
      if (std::abs(z) > 1.0) z = 0.5 * (b - root);
      zeros.push_back(z);
    }
  }
  // H(w) in w = e^{-i omega}: ((1 + w) / 2)^n prod_i (1 - z_i w) / (1 - z_i), so H(1) = 1.
  std::vector<std::complex<double>> poly{1.0};
  const auto multiply = [&](std::complex<double> c0, std::complex<double> c1) {
    std::vector<std::complex<double>> next(poly.size() + 1, 0.0);
    for (std::size_t i = 0; i < poly.size(); ++i) {
      next[i] += c0 * poly[i];
      next[i + 1] += c1 * poly[i];
    }
    poly = std::move(next);
  };
  for (int i = 0; i < n; ++i) multiply(0.5, 0.5);
  for (const std::complex<double>& z : zeros) multiply(1.0 / (1.0 - z), -z / (1.0 - z));
  std::vector<double> h(poly.size());
  for (std::size_t i = 0; i < poly.size(); ++i) h[i] = std::sqrt(2.0) * poly[i].real();
  return h;
}

void wavelet_level(std::vector<double>& values, std::size_t rows, std::size_t columns,
                   std::size_t stride, const std::vector<double>& low_pass) {
  const std::vector<double> g = wavelet_high_pass(low_pass);
  std::vector<double> scratch;
  for (std::size_t r = 0; r < rows; ++r) {
    analyse_line(values.data() + r * stride, columns, 1, low_pass, g, scratch);
  }
  for (std::size_t c = 0; c < columns; ++c) {
    analyse_line(values.data() + c, rows, stride, low_pass, g, scratch);
  }
}

void inverse_wavelet_level(std::vector<double>& values, std::size_t rows, std::size_t columns,
                           std::size_t stride, const std::vector<double>& low_pass) {
  const std::vector<double> g = wavelet_high_pass(low_pass);
  std::vector<double> scratch;
  for (std::size_t c = 0; c < columns; ++c) {
    synthesise_line(values.data() + c, rows, stride, low_pass, g, scratch);
  }
  for (std::size_t r = 0; r < rows; ++r) {
    synthesise_line(values.data() + r * stride, columns, 1, low_pass, g, scratch);
  }
}

}  // namespace riner::stripes
