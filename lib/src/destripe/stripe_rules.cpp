#include "destripe/stripe_rules.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "destripe/sinogram_ops.hpp"

namespace riner::stripes {

namespace {

// More elements than this share of a row found dead or fluctuating is the object's structure,
// not the detector's (a noiseless sinogram's columns fluctuate with the edges they cross):
// algorithm 6 then interpolates nothing.
constexpr double kMostDeadShare = 0.05;
// A column fluctuates by a fault of its own where at least this share of its fluctuation is
// its own. A body's edge sweeping across columns near its outline (a stripe-free DeepLesion
// fan scan: 19 columns taken, -8.5 dB) has at most 0.07 its own; neutron360's two failing
// elements 0.54 and 0.68, a simulated element dying part-way 0.94.
constexpr double kOwnShare = 0.25;

}  // namespace

std::size_t fft_friendly(std::size_t n) {
  for (std::size_t m = std::max<std::size_t>(n, 1);; ++m) {
    std::size_t rest = m;
    for (const std::size_t p : {2, 3, 5}) {
      while (rest % p == 0) rest /= p;
    }
    if (rest == 1) return m;
  }
}

std::size_t rank_window(std::size_t views) { return (views / 6) | 1; }

namespace {

PaddedLine padded_line(std::size_t nominal, std::size_t length) {
  return {length, static_cast<double>(length) / static_cast<double>(nominal)};
}

}  // namespace

std::size_t filtering_pad(std::size_t views) { return std::min<std::size_t>(150, views / 10); }

PaddedLine filtering_line(std::size_t views) {
  const std::size_t nominal = views + 2 * filtering_pad(views);
  return padded_line(nominal, fft_friendly(nominal));
}

std::size_t fourier_pad(std::size_t n) { return std::clamp<std::size_t>(n / 10, 16, 150); }

PaddedLine fitting_line(std::size_t columns) {
  const std::size_t nominal = columns + fourier_pad(columns);
  return padded_line(nominal, fft_friendly(nominal));
}

PaddedLine wavelet_line(std::size_t n, int levels) {
  const std::size_t block = std::size_t{1} << levels;
  const std::size_t blocks = (n + fourier_pad(n) + block - 1) / block;
  return padded_line(blocks * block, fft_friendly(blocks) * block);
}

double low_pass_gain(double k, double sigma) { return std::exp(-0.5 * (k / sigma) * (k / sigma)); }

double high_pass_gain(double k, double sigma) { return 1.0 - low_pass_gain(k, sigma); }

std::vector<double> line_gains(std::size_t n, const std::function<double(double)>& gain) {
  std::vector<double> out(n);
  for (std::size_t k = 0; k < n; ++k) out[k] = gain(static_cast<double>(std::min(k, n - k)));
  return out;
}

std::vector<double> polynomial_basis(std::size_t views, int order) {
  const auto n = static_cast<Eigen::Index>(views);
  const int terms = std::clamp(order, 0, static_cast<int>(views) - 1) + 1;
  Eigen::MatrixXd powers(n, terms);
  for (Eigen::Index v = 0; v < n; ++v) {
    const double t = 2.0 * static_cast<double>(v) / static_cast<double>(n - 1) - 1.0;
    for (int j = 0; j < terms; ++j) powers(v, j) = std::pow(t, j);
  }
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const RowMajor q = Eigen::HouseholderQR<Eigen::MatrixXd>(powers).householderQ() *
                     Eigen::MatrixXd::Identity(n, terms);
  return {q.data(), q.data() + q.size()};
}

std::vector<double> normalise_offsets(const std::vector<double>& mean, std::size_t size) {
  const std::vector<double> target = median_filter(mean, size);
  std::vector<double> offset(mean.size());
  for (std::size_t c = 0; c < mean.size(); ++c) offset[c] = mean[c] - target[c];
  return offset;
}

namespace {

// A detector's large stripe is a band whose offset steps up and down at its ends; where the
// median's bias on a curve (a body's central peak) stands out, the offset rises and falls
// smoothly: 30 columns of a stripe-free DeepLesion scan were replaced by their neighbours'
// smoothed values. A band is kept where the offset steps by half its mean or more between
// neighbouring columns within two of each end.
void keep_stepped_bands(std::vector<bool>& mask, const std::vector<double>& offset) {
  const long n = static_cast<long>(mask.size());
  long c = 0;
  while (c < n) {
    if (!mask[static_cast<std::size_t>(c)]) {
      ++c;
      continue;
    }
    long end = c;
    while (end < n && mask[static_cast<std::size_t>(end)]) ++end;
    double mean = 0.0;
    for (long i = c; i < end; ++i) mean += offset[static_cast<std::size_t>(i)];
    mean /= static_cast<double>(end - c);
    // The largest step between neighbouring columns near each end of the band.
    const auto step_near = [&](long at) {
      double most = 0.0;
      for (long i = std::max(1L, at - 2); i <= std::min(n - 1, at + 2); ++i) {
        most = std::max(most, std::fabs(offset[static_cast<std::size_t>(i)] -
                                        offset[static_cast<std::size_t>(i - 1)]));
      }
      return most;
    };
    const bool stepped =
        step_near(c) >= 0.5 * std::fabs(mean) && step_near(end) >= 0.5 * std::fabs(mean);
    if (!stepped) {
      for (long i = c; i < end; ++i) mask[static_cast<std::size_t>(i)] = false;
    }
    c = end;
  }
}

}  // namespace

LargeStripes large_stripe_offsets(const std::vector<double>& level,
                                  const std::vector<double>& smooth_level, double snr,
                                  const std::vector<std::vector<double>>& quarters,
                                  std::size_t size) {
  LargeStripes out;
  out.offset.resize(level.size());
  std::vector<bool> whole_column(level.size(), true);
  for (std::size_t c = 0; c < level.size(); ++c) {
    out.offset[c] = level[c] - smooth_level[c];
    for (const std::vector<double>& q : quarters) {
      whole_column[c] = whole_column[c] && q[c] * out.offset[c] >= 0.5 * out.offset[c] * out.offset[c];
    }
  }
  out.mask = detect_stripes(out.offset, snr, &whole_column);
  keep_stepped_bands(out.mask, out.offset);
  // What moves every column is only the offsets' part that changes from column to column: the
  // median's bias on the object's own curve (a body's central peak, 0.17 over 50 columns) is
  // broad, and took a stripe-free scan's FBP from 38.6 to 31.3 dB; a detector's offsets differ
  // element by element.
  const std::vector<double> broad = median_filter(out.offset, (size / 2) | 1);
  for (std::size_t c = 0; c < level.size(); ++c) out.offset[c] -= broad[c];
  return out;
}

std::pair<std::size_t, std::size_t> rank_quarter(std::size_t views, std::size_t drop, int q) {
  const std::size_t ranks = views - 2 * drop;
  return {drop + ranks * static_cast<std::size_t>(q) / 4,
          drop + ranks * static_cast<std::size_t>(q + 1) / 4};
}

std::size_t large_stripe_drop(std::size_t views, double drop_ratio) {
  return static_cast<std::size_t>(0.5 * std::clamp(drop_ratio, 0.0, 0.8) * static_cast<double>(views));
}

std::vector<bool> dead_columns(const ColumnFluctuation& fluctuation, std::size_t size, double snr) {
  const std::size_t columns = fluctuation.total.size();
  const std::vector<double> background = median_filter(fluctuation.total, size);
  std::vector<double> ratio(columns, 1.0);
  std::vector<bool> allowed(columns, true);
  for (std::size_t c = 0; c < columns; ++c) {
    if (background[c] > 0.0) ratio[c] = fluctuation.total[c] / background[c];
    allowed[c] = ratio[c] <= 1.0 || fluctuation.own[c] >= kOwnShare * fluctuation.total[c];
  }
  std::vector<bool> mask = detect_stripes(ratio, snr, &allowed);
  for (std::size_t c = 0; c < std::min<std::size_t>(2, columns); ++c) {
    mask[c] = false;
    mask[columns - 1 - c] = false;
  }
  const auto found = static_cast<double>(std::count(mask.begin(), mask.end(), true));
  if (found > kMostDeadShare * static_cast<double>(columns)) mask.assign(columns, false);
  return mask;
}

}  // namespace riner::stripes
