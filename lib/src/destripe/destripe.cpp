#include "riner/destripe.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <memory>
#include <optional>
#include <unsupported/Eigen/FFT>

#include "analytic/fbp_setup.hpp"
#include "cl/device_access.hpp"
#include "destripe/device_destripe.hpp"
#include "destripe/sinogram_ops.hpp"
#include "destripe/stripe_rules.hpp"
#include "destripe/wavelets.hpp"
#include "model/noise_evidence.hpp"
#include "model/stuck_elements.hpp"
#include "riner/error.hpp"

namespace riner {

namespace {

using stripes::Sinogram;
using stripes::StripeSettings;

// The literature's Gaussian widths (algotom's): filtering's low-pass along the views, fitting's
// across columns, the wavelet filter's high-pass along the views.
double literature_sigma(DestripeMethod method) {
  switch (method) {
    case DestripeMethod::kFitting: return 10.0;
    case DestripeMethod::kWavelet: return 1.0;
    default: return 3.0;
  }
}

// The literature's windows (algotom's remove_all_stripe: 21 and 51).
constexpr std::size_t kSmallWindow = 21;
constexpr std::size_t kLargeWindow = 51;
// The combination's sorting window. Its large-stripe step has already moved every column's
// offset onto its 51 neighbours' median, so what its sorting step is left with is narrow (a
// partial stripe, a column whose offset the large step's median misread), and a median of 5
// outvotes any stripe up to 2 elements wide; the literature's 21 only flattens the object's
// detail narrower than 10 columns. On the ten DeepLesion slices at the paper's protocol: 21
// 29.01 dB, 11 29.73, 7 30.07, 5 30.25, 3 30.40, none 30.45 (the paper's Super: 29.11); on the
// shared real scans 5 leaves the fewest rings (3 and none leave more on neutron360 and the
// tooth) and neutron360 loses 43 pixels of object instead of 361 (docs/history/RESULTS.md).
constexpr std::size_t kCombinationWindow = 5;

// The method's window (the literature's, or the combination's) unless one is given, odd and
// within the detector. Widening it by the widest stripe the column means show was tried: on a
// sinogram of smooth blobs 20-25 columns wide the blobs' peaks read as stripes 25 wide, and
// normalise's error went from 0.019 to 0.034. The literature's windows fit detectors of 500 to
// 2560 columns; on a narrow one a default window wider than an eighth of it spans the object
// (64 columns with 51: `all` took an FBP from 18.1 to 12.5 dB), so a default is no wider than
// that. A given one stands.
std::size_t window(std::size_t given, std::size_t method_default, std::size_t columns) {
  const std::size_t size =
      given ? given : std::min(method_default, std::max<std::size_t>(3, columns / 8));
  const std::size_t most = columns % 2 == 1 ? columns : columns - 1;
  return std::max<std::size_t>(std::min(size | 1, most), 1);
}

std::vector<double> column_means(const Sinogram& s, std::size_t from, std::size_t to) {
  std::vector<double> mean(s.columns, 0.0);
  for (std::size_t v = from; v < to; ++v) {
    for (std::size_t c = 0; c < s.columns; ++c) mean[c] += s.at(v, c);
  }
  for (double& m : mean) m /= static_cast<double>(std::max<std::size_t>(1, to - from));
  return mean;
}

void subtract_column_offsets(Sinogram& s, const std::vector<double>& offset) {
  for (std::size_t v = 0; v < s.views; ++v) {
    for (std::size_t c = 0; c < s.columns; ++c) s.at(v, c) -= offset[c];
  }
}

// Each column's mean over the views moved onto the median of its neighbours' means.
void normalise(Sinogram& s, std::size_t size) {
  subtract_column_offsets(s, stripes::normalise_offsets(column_means(s, 0, s.views), size));
}

// Algorithm 3: a stripe is an offset of one column, which sorting turns into an offset of one
// column of a smooth image; a median across columns removes it there.
void sorting(Sinogram& s, std::size_t size, std::size_t rank_window) {
  const stripes::SortedColumns sorted = stripes::sort_columns(s);
  const Sinogram filtered = stripes::median_across_columns(sorted.sorted, size);
  s = stripes::unsort_columns(stripes::smooth_along_ranks(sorted.sorted, filtered, rank_window),
                              sorted.view);
}

// Each line `stride` apart in `values` of n values multiplied in Fourier space by
// gain(min(k, n - k)), the distance of bin k from the zero frequency.
void filter_lines(std::vector<double>& values, std::size_t first, std::size_t lines,
                  std::size_t line_step, std::size_t n, std::size_t stride,
                  const std::function<double(double)>& gain) {
  const std::vector<double> gains = stripes::line_gains(n, gain);
  Eigen::FFT<double> fft;
  std::vector<double> line(n), back;
  std::vector<std::complex<double>> spectrum;
  for (std::size_t l = 0; l < lines; ++l) {
    const std::size_t start = first + l * line_step;
    for (std::size_t i = 0; i < n; ++i) line[i] = values[start + i * stride];
    fft.fwd(spectrum, line);
    for (std::size_t k = 0; k < n; ++k) spectrum[k] *= gains[k];
    fft.inv(back, spectrum);
    for (std::size_t i = 0; i < n; ++i) values[start + i * stride] = back[i];
  }
}

// Algorithm 2: only each column's slow variation along the views (a Gaussian low-pass, the
// columns mirrored at both ends) goes through the sorting; the fast part is kept as measured.
void filtering(Sinogram& s, std::size_t size, std::size_t rank_window, double sigma) {
  const std::size_t pad = stripes::filtering_pad(s.views);
  const stripes::PaddedLine line = stripes::filtering_line(s.views);
  const std::size_t n = line.length;
  sigma *= line.bins_scale;
  // Each column mirrored about its first and last views ('reflect' without repeating them).
  Sinogram padded{n, s.columns, std::vector<double>(n * s.columns)};
  for (std::size_t i = 0; i < n; ++i) {
    long v = static_cast<long>(i) - static_cast<long>(pad);
    if (v < 0) v = -v;
    if (v >= static_cast<long>(s.views)) v = 2 * static_cast<long>(s.views) - v - 2;
    const auto from = static_cast<std::size_t>(std::clamp(v, 0L, static_cast<long>(s.views) - 1));
    for (std::size_t c = 0; c < s.columns; ++c) padded.at(i, c) = s.at(from, c);
  }
  filter_lines(padded.values, 0, s.columns, 1, n, s.columns,
               [&](double f) { return stripes::low_pass_gain(f, sigma); });
  Sinogram smooth = s;
  for (std::size_t v = 0; v < s.views; ++v) {
    for (std::size_t c = 0; c < s.columns; ++c) smooth.at(v, c) = padded.at(v + pad, c);
  }
  Sinogram corrected = smooth;
  sorting(corrected, size, rank_window);
  for (std::size_t i = 0; i < s.values.size(); ++i) {
    s.values[i] += corrected.values[i] - smooth.values[i];
  }
}

// Algorithm 1: each column's trend along the views (a least-squares polynomial) carries its
// stripe; the same trends smoothed across columns (a Gaussian in Fourier space) do not, and
// their difference is taken off. Vo divides by the fit and multiplies by the smoothed one, for
// sinograms whose stripes are gains; in rho a response is an offset, and a quotient of fits is
// unstable where the sinogram reads air (about 0), so the difference is subtracted.
void fitting(Sinogram& s, int order, double sigma) {
  const std::vector<double> basis = stripes::polynomial_basis(s.views, order);
  const auto views = static_cast<Eigen::Index>(s.views);
  const auto terms = static_cast<Eigen::Index>(basis.size() / s.views);
  using RowMajor = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  const Eigen::Map<const RowMajor> q(basis.data(), views, terms);
  const Eigen::Map<const RowMajor> data(s.values.data(), views, static_cast<Eigen::Index>(s.columns));
  const RowMajor fitted = q * (q.transpose() * data);
  Sinogram trend{s.views, s.columns, std::vector<double>(fitted.data(), fitted.data() + fitted.size())};
  const stripes::PaddedLine line = stripes::fitting_line(s.columns);
  const std::size_t columns = line.length;
  sigma *= line.bins_scale;
  Sinogram smooth = stripes::periodic_extension(trend, s.views, columns);
  filter_lines(smooth.values, 0, s.views, columns, columns, 1,
               [&](double k) { return stripes::low_pass_gain(k, sigma); });
  smooth = stripes::crop(smooth, s.views, s.columns);
  for (std::size_t i = 0; i < s.values.size(); ++i) s.values[i] -= trend.values[i] - smooth.values[i];
}

// The levels a views x columns sinogram takes: `wanted`, or as many as leave both sides at
// least 8 long, up to 4. Deeper levels take the object's own structure near the axis: on the
// ten DeepLesion slices (500 columns, db5) levels 2, 3, 4, 5, 7 gave 28.5, 32.0, 32.1, 28.4,
// 17.6 dB (tomopy's default, as many as fit, is the last; the paper's WaveFFT reads 20.7).
int wavelet_levels(int wanted, std::size_t views, std::size_t columns) {
  if (wanted > 0) return wanted;
  int levels = 0;
  while (levels < 4 && (std::min(views, columns) >> (levels + 1)) >= 8) ++levels;
  return std::max(levels, 1);
}

// Münch et al.: a stripe is constant along the views and narrow across columns, so in a 2D
// wavelet decomposition it lives in each level's band of details across columns and
// approximations along the views; there, along the views, it is the zero frequency, and a
// Gaussian high-pass (1 - exp(-k^2 / 2 sigma^2)) takes it out. The sinogram is padded
// (continuous when wrapped, periodic_extension) to a multiple of 2^levels on both sides.
void wavelet_fft(Sinogram& s, int levels, int order, double sigma) {
  const std::vector<double> low_pass = stripes::daubechies_filter(order);
  const stripes::PaddedLine along_views = stripes::wavelet_line(s.views, levels);
  const std::size_t views = along_views.length;
  const std::size_t columns = stripes::wavelet_line(s.columns, levels).length;
  sigma *= along_views.bins_scale;  // the band's lines run along the views
  Sinogram padded = stripes::periodic_extension(s, views, columns);
  for (int l = 0; l < levels; ++l) {
    const std::size_t rows_l = views >> l, columns_l = columns >> l;
    stripes::wavelet_level(padded.values, rows_l, columns_l, columns, low_pass);
    const std::size_t band_rows = rows_l / 2;
    filter_lines(padded.values, columns_l / 2, columns_l - columns_l / 2, 1, band_rows, columns,
                 [&](double k) { return stripes::high_pass_gain(k, sigma); });
  }
  for (int l = levels - 1; l >= 0; --l) {
    stripes::inverse_wavelet_level(padded.values, views >> l, columns >> l, columns, low_pass);
  }
  s = stripes::crop(padded, s.views, s.columns);
}

// Algorithm 5: large stripes found from the sorted columns' means against their median across
// columns (the extremes of each column dropped), every column's offset normalised, and the
// stripes' columns replaced by the smoothed sorted values.
std::vector<bool> large_stripes(Sinogram& s, std::size_t size, double snr, double drop_ratio) {
  const std::size_t drop = stripes::large_stripe_drop(s.views, drop_ratio);
  const stripes::SortedColumns sorted = stripes::sort_columns(s);
  const Sinogram smooth = stripes::median_across_columns(sorted.sorted, size);
  std::vector<std::vector<double>> quarters;
  for (int q = 0; q < 4; ++q) {
    const auto [first, last] = stripes::rank_quarter(s.views, drop, q);
    const std::vector<double> a = column_means(sorted.sorted, first, last);
    const std::vector<double> b = column_means(smooth, first, last);
    quarters.emplace_back(a.size());
    for (std::size_t c = 0; c < a.size(); ++c) quarters.back()[c] = a[c] - b[c];
  }
  const stripes::LargeStripes found = stripes::large_stripe_offsets(
      column_means(sorted.sorted, drop, s.views - drop), column_means(smooth, drop, s.views - drop),
      snr, quarters, size);
  subtract_column_offsets(s, found.offset);
  // A column less its offset ranks its views as before: the first sort's order serves.
  const Sinogram corrected = stripes::unsort_columns(smooth, sorted.view);
  for (std::size_t v = 0; v < s.views; ++v) {
    for (std::size_t c = 0; c < s.columns; ++c) {
      if (found.mask[c]) s.at(v, c) = corrected.at(v, c);
    }
  }
  return found.mask;
}

// The twin of stripe_columns.cl's view_deviations and column_fluctuation.
stripes::ColumnFluctuation column_fluctuation(const Sinogram& s) {
  const long half = static_cast<long>(stripes::kFluctuationWindow / 2);
  std::vector<double> deviation(s.views * s.columns);
  for (std::size_t v = 0; v < s.views; ++v) {
    for (std::size_t c = 0; c < s.columns; ++c) {
      double mean = 0.0;
      for (long d = -half; d <= half; ++d) {
        mean += s.at(stripes::reflect(static_cast<long>(v) + d, s.views), c);
      }
      deviation[v * s.columns + c] =
          std::fabs(s.at(v, c) - mean / static_cast<double>(2 * half + 1));
    }
  }
  const long near = static_cast<long>(stripes::kNeighbourNear);
  const long far = static_cast<long>(stripes::kNeighbourFar);
  const long span = static_cast<long>(stripes::kNeighbourSpan);
  const long views = static_cast<long>(s.views), columns = static_cast<long>(s.columns);
  stripes::ColumnFluctuation out{std::vector<double>(s.columns, 0.0),
                                 std::vector<double>(s.columns, 0.0)};
  for (long c = 0; c < columns; ++c) {
    for (long v = 0; v < views; ++v) {
      double most = 0.0;
      for (long u = std::max(0L, v - span); u <= std::min(views - 1, v + span); ++u) {
        for (long k = near; k <= far; ++k) {
          for (const long n : {c - k, c + k}) {
            if (n >= 0 && n < columns)
              most = std::max(most, deviation[static_cast<std::size_t>(u * columns + n)]);
          }
        }
      }
      const double d = deviation[static_cast<std::size_t>(v * columns + c)];
      out.total[static_cast<std::size_t>(c)] += d;
      out.own[static_cast<std::size_t>(c)] += std::max(0.0, d - most);
    }
  }
  return out;
}

// Algorithm 6: an element that does not follow the scan (dead: too little fluctuation along
// the views; fluctuating: too much, of its own) against its neighbours is interpolated from them.
std::vector<bool> dead_stripes(Sinogram& s, std::size_t size, double snr) {
  const std::vector<bool> mask = stripes::dead_columns(column_fluctuation(s), size, snr);
  stripes::interpolate_columns(s, stripes::interpolation_plan(mask));
  return mask;
}

bool finds_dead(DestripeMethod method) {
  return method == DestripeMethod::kDead || method == DestripeMethod::kAll;
}

bool sorts_readings(DestripeMethod method) {
  return method == DestripeMethod::kSorting || method == DestripeMethod::kFiltering ||
         method == DestripeMethod::kAll;
}

// Algorithm 6 judges an element's fluctuation against its neighbours' through a threshold
// fitted to the sorted ratios, which a wide spread pushes below zero: a column stuck at 0 or
// at 3 on a simulated scan went unfound. A column steady over the views while its neighbours
// vary is the training's stuck element (model/stuck_elements.hpp), found on the whole scan.
// The measurement is moved in and out, not copied.
std::vector<std::uint8_t> steady_elements(const Geometry& g, Array& measurement) {
  Scan scan{std::move(measurement), g, 0};
  std::vector<std::uint8_t> stuck;
  try {
    stuck = model::stuck_elements(scan, model::reading_noise(scan).sigma);
  } catch (...) {
    measurement = std::move(scan.measurement);
    throw;
  }
  measurement = std::move(scan.measurement);
  return stuck;
}

// Row r's steady columns, interpolated from their neighbours in `row` (views x columns) before
// the method runs, as algotom's combination removes dead stripes first.
std::vector<bool> interpolate_stuck(const std::vector<std::uint8_t>& stuck, std::size_t r,
                                    std::size_t views, std::size_t columns,
                                    std::vector<float>& row) {
  std::vector<bool> mask(columns, false);
  if (stuck.empty()) return mask;
  for (std::size_t c = 0; c < columns; ++c) mask[c] = stuck[r * columns + c] != 0;
  if (std::find(mask.begin(), mask.end(), true) == mask.end()) return mask;
  Sinogram s{views, columns, std::vector<double>(row.begin(), row.end())};
  stripes::interpolate_columns(s, stripes::interpolation_plan(mask));
  std::transform(s.values.begin(), s.values.end(), row.begin(),
                 [](double x) { return static_cast<float>(x); });
  return mask;
}

// `method` on one sinogram on the CPU; the masks of dead and large stripes where it finds them.
void destripe_on_cpu(DestripeMethod method, const StripeSettings& k, Sinogram& s,
                     std::vector<bool>& dead, std::vector<bool>& large) {
  switch (method) {
    case DestripeMethod::kNormalise: normalise(s, k.size); break;
    case DestripeMethod::kSorting:
      sorting(s, k.size, k.rank_window);
      break;
    case DestripeMethod::kFiltering:
      filtering(s, k.size, k.rank_window, k.sigma);
      break;
    case DestripeMethod::kFitting: fitting(s, k.fit_order, k.sigma); break;
    case DestripeMethod::kWavelet: wavelet_fft(s, k.levels, k.wavelet_order, k.sigma); break;
    case DestripeMethod::kLarge: large = large_stripes(s, k.large_size, k.snr, k.drop_ratio); break;
    case DestripeMethod::kDead: dead = dead_stripes(s, k.large_size, k.snr); break;
    case DestripeMethod::kAll:
      dead = dead_stripes(s, k.large_size, k.snr);
      large = large_stripes(s, k.large_size, k.snr, k.drop_ratio);
      sorting(s, k.size, k.rank_window);
      break;
  }
}

}  // namespace

DestripeMethod parse_destripe_method(std::string_view name) {
  for (DestripeMethod m : {DestripeMethod::kNormalise, DestripeMethod::kSorting,
                           DestripeMethod::kFiltering, DestripeMethod::kFitting,
                           DestripeMethod::kWavelet, DestripeMethod::kLarge,
                           DestripeMethod::kDead, DestripeMethod::kAll}) {
    if (name == destripe_method_name(m)) return m;
  }
  throw InputError("a destripe method is normalise, sorting, filtering, fitting, wavelet, large, "
                   "dead or all (got \"" +
                   std::string(name) + "\")");
}

const char* destripe_method_name(DestripeMethod method) {
  switch (method) {
    case DestripeMethod::kNormalise: return "normalise";
    case DestripeMethod::kSorting: return "sorting";
    case DestripeMethod::kFiltering: return "filtering";
    case DestripeMethod::kFitting: return "fitting";
    case DestripeMethod::kWavelet: return "wavelet";
    case DestripeMethod::kLarge: return "large";
    case DestripeMethod::kDead: return "dead";
    case DestripeMethod::kAll: return "all";
  }
  return "?";
}

Array destripe(const Array& measurement, const Geometry& g, const DestripeOptions& options,
               DestripeReport* report) {
  g.validate();
  check_array(measurement, "destripe");
  g.check_measurement_shape(measurement.shape);
  const std::size_t views = g.n_views(), columns = g.n_u, rows = g.is_3d() ? g.n_v : 1;
  if (views < 8 || columns < 8) {
    throw InputError("stripe removal needs at least 8 views and 8 columns (the scan has " +
                     std::to_string(views) + " x " + std::to_string(columns) + ")");
  }
  if (!(options.snr > 0.0) || !(options.sigma >= 0.0) || !std::isfinite(options.sigma)) {
    throw InputError("destripe: snr must be positive and sigma positive (0: the method's own)");
  }
  if (options.fit_order < 0 || options.fit_order > 10) {
    throw InputError("destripe: the fitting order must be 0..10 (got " +
                     std::to_string(options.fit_order) + ")");
  }
  if (options.wavelet_order < 1 || options.wavelet_order > 12) {
    throw InputError("destripe: the wavelet's Daubechies order must be 1..12 (got " +
                     std::to_string(options.wavelet_order) + ")");
  }
  if (options.levels < 0 || options.levels > 10) {
    throw InputError("destripe: the wavelet levels must be 1..10, or 0 for as many as fit (got " +
                     std::to_string(options.levels) + ")");
  }
  StripeSettings settings;
  settings.size = window(options.size,
                         options.method == DestripeMethod::kAll ? kCombinationWindow : kSmallWindow,
                         columns);
  settings.large_size = window(options.large_size, kLargeWindow, columns);
  settings.snr = options.snr;
  settings.sigma = options.sigma > 0.0 ? options.sigma : literature_sigma(options.method);
  settings.fit_order = options.fit_order;
  settings.levels = options.method == DestripeMethod::kWavelet
                        ? wavelet_levels(options.levels, views, columns)
                        : 0;
  settings.wavelet_order = options.wavelet_order;
  settings.drop_ratio = options.drop_ratio;
  settings.rank_window = options.rank_window ? std::min(options.rank_window | 1, views | 1)
                                             : stripes::rank_window(views);
  // Every per-reading step on the device where it holds a column for the sorting step; the
  // device outlives the steps that hold its context.
  std::optional<Device> opened;
  std::unique_ptr<stripes::DeviceDestripe> device;
  if (options.engine == Engine::kOpenCL) {
    opened = options.device ? *options.device : Device::open();
    cl::Context& context = cl::context_of(*opened);
    if (stripes::DeviceDestripe::supported(context, options.method, views, settings)) {
      device = std::make_unique<stripes::DeviceDestripe>(context, options.method, settings, views,
                                                         columns);
    }
  }
  Array out = measurement;
  DestripeReport local;
  // An element with no finite reading is dead as surely as a stuck one (the training says
  // "no finite reading"); the repair below fills it, and the report names it.
  std::vector<bool> unread(rows * columns, true);
  const float largest = largest_reading(measurement, views);
  for (std::size_t v = 0; v < views; ++v) {
    const float* line = measurement.data.data() + v * rows * columns;
    for (std::size_t e = 0; e < rows * columns; ++e) {
      if (std::fabs(line[e]) <= largest) unread[e] = false;
    }
  }
  local.non_finite_replaced = analytic::repair_non_finite(out, columns, rows);
  const std::vector<std::uint8_t> stuck =
      finds_dead(options.method) ? steady_elements(g, out) : std::vector<std::uint8_t>{};
  // Per element, shaped like alpha: [columns] for a sinogram, [rows, columns] for a stack.
  local.removed = g.is_3d() ? Array({rows, columns}) : Array({columns});
  local.size = settings.size;
  local.large_size = settings.large_size;
  local.rank_window = sorts_readings(options.method) ? settings.rank_window : 0;
  local.sigma = settings.sigma;
  local.levels = settings.levels;
  // Each row's sinogram as floats, the readings' own type: the device takes them as they are,
  // the CPU twins in double. What was removed is each column's mean before less its mean after.
  std::vector<float> row(views * columns);
  std::vector<double> column_before(columns), column_after(columns);
  const auto column_sums = [&](std::vector<double>& sums) {
    std::fill(sums.begin(), sums.end(), 0.0);
    for (std::size_t v = 0; v < views; ++v) {
      const float* line = row.data() + v * columns;
      for (std::size_t c = 0; c < columns; ++c) sums[c] += line[c];
    }
  };
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t v = 0; v < views; ++v) {
      const float* from = out.data.data() + (v * rows + r) * columns;
      std::copy(from, from + columns, row.begin() + static_cast<std::ptrdiff_t>(v * columns));
    }
    column_sums(column_before);
    const std::vector<bool> steady = interpolate_stuck(stuck, r, views, columns, row);
    std::vector<bool> dead, large;
    if (device) {
      device->run(row, dead, large);
    } else {
      Sinogram s{views, columns, std::vector<double>(row.begin(), row.end())};
      destripe_on_cpu(options.method, settings, s, dead, large);
      std::transform(s.values.begin(), s.values.end(), row.begin(),
                     [](double x) { return static_cast<float>(x); });
    }
    column_sums(column_after);
    for (std::size_t c = 0; c < columns; ++c) {
      if ((c < dead.size() && dead[c]) || steady[c] || unread[r * columns + c]) {
        local.dead.push_back(r * columns + c);
      }
      if (c < large.size() && large[c]) local.large.push_back(r * columns + c);
      local.removed.data[r * columns + c] =
          static_cast<float>((column_before[c] - column_after[c]) / static_cast<double>(views));
    }
    for (std::size_t v = 0; v < views; ++v) {
      const float* from = row.data() + v * columns;
      std::copy(from, from + columns,
                out.data.begin() + static_cast<std::ptrdiff_t>((v * rows + r) * columns));
    }
  }
  if (report != nullptr) *report = std::move(local);
  return out;
}

}  // namespace riner
