// What the classical stripe-removal methods decide from a sinogram's small summaries (padding
// lengths, filter gains, the fitting basis, offsets and masks from column profiles): shared by
// the CPU path (destripe.cpp) and the device path (device_destripe.cpp), which differ only in
// where the per-reading steps run.
#pragma once

#include <cstddef>
#include <functional>
#include <utility>
#include <vector>

namespace riner::stripes {

// A method's settings with the literature's defaults resolved for one scan.
struct StripeSettings {
  std::size_t size = 21;        // the median window across columns (odd)
  std::size_t large_size = 51;  // the window for large and dead stripes (odd)
  double snr = 3.0;
  double sigma = 3.0;  // the method's Gaussian width (bins)
  int fit_order = 2;
  int levels = 1;         // wavelet levels
  int wavelet_order = 9;  // Daubechies'
  double drop_ratio = 0.1;
  std::size_t rank_window = 1;  // the sorting step's mean of its correction along the ranks (odd)
};

// The sorting step's window along the ranks: a sixth of the views (odd). A detector's offset
// moves a column's sorted readings alike at neighbouring ranks, while the median's bias on the
// object's own detail (a peak narrower than the window across columns) comes and goes from one
// rank to the next: the mean keeps the first and averages the second away.
std::size_t rank_window(std::size_t views);

// Algorithm 6's moving mean along the views.
constexpr std::size_t kFluctuationWindow = 11;
// Which of a column's fluctuation is its own: what its deviation from that mean has beyond the
// largest deviation of the columns kNeighbourNear..kNeighbourFar to either side (past a fault
// three elements wide) within kNeighbourSpan views (an edge reaches them a few views later).
constexpr std::size_t kNeighbourNear = 3, kNeighbourFar = 5, kNeighbourSpan = 6;

// Per column: the summed deviation along the views (algorithm 6's fluctuation) and its own part.
struct ColumnFluctuation {
  std::vector<double> total, own;
};

// The smallest length >= n whose only prime factors are 2, 3 and 5: a Fourier filter's line
// of that length takes n log n (a prime one, 797 say, n^2: 1.8 s instead of 20 ms for fitting
// a 720 x 725 sinogram on the CPU).
std::size_t fft_friendly(std::size_t n);

// A padded line for a Fourier filter: its length, FFT-friendly, and the factor a width in bins
// of the literature's padded length takes at this one (the same frequencies cut).
struct PaddedLine {
  std::size_t length = 0;
  double bins_scale = 1.0;
};
// The padding a Fourier filter of a line of n values gets (algotom's: a tenth, at most 150),
// at least 16 so that the wrap-around blend is gentle.
std::size_t fourier_pad(std::size_t n);
// filtering's padding of each column at both ends (algotom's: a tenth of the views, at most
// 150), and its padded column: views + 2 pad, made FFT-friendly with more of the mirrored
// column at the end.
std::size_t filtering_pad(std::size_t views);
PaddedLine filtering_line(std::size_t views);
// fitting's padded row: the columns and their Fourier pad.
PaddedLine fitting_line(std::size_t columns);
// The wavelet filter's padded side of n: n plus its Fourier pad, a multiple of 2^levels.
PaddedLine wavelet_line(std::size_t n, int levels);

// Gains at distance k (bins) from the zero frequency: the Gaussian low-pass and its complement.
double low_pass_gain(double k, double sigma);
double high_pass_gain(double k, double sigma);
// A line of n's gains at every DFT bin: gain(min(k, n - k)).
std::vector<double> line_gains(std::size_t n, const std::function<double(double)>& gain);

// fitting's basis: the orthonormal polynomials up to `order` (at most views - 1) over the views,
// row-major [views][terms]; terms is basis.size() / views.
std::vector<double> polynomial_basis(std::size_t views, int order);

// normalise: what to take off each column, its mean minus its neighbours' median of means.
std::vector<double> normalise_offsets(const std::vector<double>& mean, std::size_t size);

// Algorithm 5's decision: each column's offset (its sorted level minus the smoothed level) and
// the columns whose offset stands out as a large stripe.
struct LargeStripes {
  std::vector<double> offset;
  std::vector<bool> mask;
};
// `quarters`: each quarter of the trimmed ranks' level minus smoothed level, per column (four
// vectors). A detector's stripe shifts a column's whole sorted profile, so every quarter carries
// its offset; an object's edge shifts some ranks only (a dense rod's top quarter, its air
// none), and such a column is no stripe: only columns whose every quarter carries at least
// half the offset, with its sign, may stand out.
// Bands that do not step at both ends are no stripes; the offsets returned are what changes
// from column to column (less their median over half of `size`).
LargeStripes large_stripe_offsets(const std::vector<double>& level,
                                  const std::vector<double>& smooth_level, double snr,
                                  const std::vector<std::vector<double>>& quarters,
                                  std::size_t size);
// The ranks [first, last) of quarter q (0..3) of the trimmed ranks [drop, views - drop).
std::pair<std::size_t, std::size_t> rank_quarter(std::size_t views, std::size_t drop, int q);
// The share of each sorted column's extremes large-stripe removal leaves out, as views per end.
std::size_t large_stripe_drop(std::size_t views, double drop_ratio);

// Algorithm 6's decision: the columns whose fluctuation along the views stands out of their
// neighbours' (dead: too little; fluctuating: too much, and much of it the column's own); none
// when more than a share of the row does (that is the object's structure, not the detector's).
std::vector<bool> dead_columns(const ColumnFluctuation& fluctuation, std::size_t size, double snr);

}  // namespace riner::stripes
