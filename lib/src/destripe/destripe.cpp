#include "riner/destripe.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <memory>
#include <unsupported/Eigen/FFT>

#include "analytic/fbp_setup.hpp"
#include "cl/device_access.hpp"
#include "ops/stripe_sorting.hpp"
#include "destripe/sinogram_ops.hpp"
#include "riner/error.hpp"

namespace riner {

namespace {

using stripes::Sinogram;

// The literature's windows (algotom's remove_all_stripe: 21 and 51).
constexpr std::size_t kSmallWindow = 21;
constexpr std::size_t kLargeWindow = 51;
// Algorithm 6's moving mean along the views.
constexpr std::size_t kFluctuationWindow = 11;
// More elements than this share of a row found dead or fluctuating is the object's structure,
// not the detector's (a noiseless sinogram's columns fluctuate with the edges they cross):
// algorithm 6 then interpolates nothing.
constexpr double kMostDeadShare = 0.05;

// The literature's window unless one is given, odd and within the detector. Widening them by
// the widest stripe the column means show was tried: on a sinogram of smooth blobs 20-25
// columns wide the blobs' peaks read as stripes 25 wide, and normalise's error went from 0.019
// to 0.034.
std::size_t window(std::size_t given, std::size_t literature, std::size_t columns) {
  const std::size_t size = given ? given : literature;
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

// Each column's mean over the views moved onto the median of its neighbours' means.
void normalise(Sinogram& s, std::size_t size) {
  const std::vector<double> mean = column_means(s, 0, s.views);
  const std::vector<double> target = stripes::median_filter(mean, size);
  for (std::size_t v = 0; v < s.views; ++v) {
    for (std::size_t c = 0; c < s.columns; ++c) s.at(v, c) -= mean[c] - target[c];
  }
}

// Algorithm 3: a stripe is an offset of one column, which sorting turns into an offset of one
// column of a smooth image; a median across columns removes it there. On the device when one is
// given and holds a column (the CPU twin below otherwise).
void sorting(Sinogram& s, std::size_t size, ops::StripeSortingOp* device = nullptr) {
  if (device != nullptr) {
    const std::vector<float> in(s.values.begin(), s.values.end());
    const std::vector<float> out = device->run(in, size);
    s.values.assign(out.begin(), out.end());
    return;
  }
  const stripes::SortedColumns sorted = stripes::sort_columns(s);
  s = stripes::unsort_columns(stripes::median_across_columns(sorted.sorted, size), sorted.view);
}

// Algorithm 2: only each column's slow variation along the views (a Gaussian low-pass, the
// columns mirrored at both ends) goes through the sorting; the fast part is kept as measured.
void filtering(Sinogram& s, std::size_t size, double sigma, ops::StripeSortingOp* device) {
  const std::size_t pad = std::min<std::size_t>(150, s.views / 10);
  const std::size_t n = s.views + 2 * pad;
  Sinogram smooth = s;
  Eigen::FFT<double> fft;
  std::vector<double> line(n), back;
  std::vector<std::complex<double>> spectrum;
  for (std::size_t c = 0; c < s.columns; ++c) {
    for (std::size_t i = 0; i < n; ++i) {
      long v = static_cast<long>(i) - static_cast<long>(pad);
      if (v < 0) v = -v;  // mirrored about the first view ('reflect' without repeating it)
      if (v >= static_cast<long>(s.views)) v = 2 * static_cast<long>(s.views) - v - 2;
      line[i] = s.at(static_cast<std::size_t>(std::clamp(v, 0L, static_cast<long>(s.views) - 1)), c);
    }
    fft.fwd(spectrum, line);
    for (std::size_t k = 0; k < n; ++k) {
      const double f = static_cast<double>(std::min(k, n - k));
      spectrum[k] *= std::exp(-0.5 * (f / sigma) * (f / sigma));
    }
    fft.inv(back, spectrum);
    for (std::size_t v = 0; v < s.views; ++v) smooth.at(v, c) = back[v + pad];
  }
  Sinogram corrected = smooth;
  sorting(corrected, size, device);
  for (std::size_t i = 0; i < s.values.size(); ++i) {
    s.values[i] += corrected.values[i] - smooth.values[i];
  }
}

// Algorithm 5: large stripes found from the sorted columns' means against their median across
// columns (the extremes of each column dropped), every column's offset normalised, and the
// stripes' columns replaced by the smoothed sorted values.
std::vector<bool> large_stripes(Sinogram& s, std::size_t size, double snr, double drop_ratio) {
  const std::size_t drop = static_cast<std::size_t>(
      0.5 * std::clamp(drop_ratio, 0.0, 0.8) * static_cast<double>(s.views));
  const stripes::SortedColumns sorted = stripes::sort_columns(s);
  const Sinogram smooth = stripes::median_across_columns(sorted.sorted, size);
  const std::vector<double> level = column_means(sorted.sorted, drop, s.views - drop);
  const std::vector<double> smooth_level = column_means(smooth, drop, s.views - drop);
  std::vector<double> offset(s.columns);
  for (std::size_t c = 0; c < s.columns; ++c) offset[c] = level[c] - smooth_level[c];
  const std::vector<bool> mask = stripes::detect_stripes(offset, snr);
  for (std::size_t v = 0; v < s.views; ++v) {
    for (std::size_t c = 0; c < s.columns; ++c) s.at(v, c) -= offset[c];
  }
  const stripes::SortedColumns order = stripes::sort_columns(s);
  const Sinogram corrected = stripes::unsort_columns(smooth, order.view);
  for (std::size_t v = 0; v < s.views; ++v) {
    for (std::size_t c = 0; c < s.columns; ++c) {
      if (mask[c]) s.at(v, c) = corrected.at(v, c);
    }
  }
  return mask;
}

// Algorithm 6: an element that does not follow the scan (dead: too little fluctuation along
// the views; fluctuating: too much) against its neighbours is interpolated from them.
std::vector<bool> dead_stripes(Sinogram& s, std::size_t size, double snr) {
  const long half = static_cast<long>(kFluctuationWindow / 2);
  std::vector<double> fluctuation(s.columns, 0.0);
  for (std::size_t c = 0; c < s.columns; ++c) {
    for (std::size_t v = 0; v < s.views; ++v) {
      double mean = 0.0;
      for (long d = -half; d <= half; ++d) {
        mean += s.at(stripes::reflect(static_cast<long>(v) + d, s.views), c);
      }
      fluctuation[c] += std::fabs(s.at(v, c) - mean / static_cast<double>(2 * half + 1));
    }
  }
  const std::vector<double> background = stripes::median_filter(fluctuation, size);
  std::vector<double> ratio(s.columns, 1.0);
  for (std::size_t c = 0; c < s.columns; ++c) {
    if (background[c] > 0.0) ratio[c] = fluctuation[c] / background[c];
  }
  std::vector<bool> mask = stripes::detect_stripes(ratio, snr);
  for (std::size_t c = 0; c < std::min<std::size_t>(2, s.columns); ++c) {
    mask[c] = false;
    mask[s.columns - 1 - c] = false;
  }
  const auto found = static_cast<double>(std::count(mask.begin(), mask.end(), true));
  if (found > kMostDeadShare * static_cast<double>(s.columns)) mask.assign(s.columns, false);
  stripes::interpolate_columns(s, mask);
  return mask;
}

}  // namespace

DestripeMethod parse_destripe_method(std::string_view name) {
  for (DestripeMethod m : {DestripeMethod::kNormalise, DestripeMethod::kSorting,
                           DestripeMethod::kFiltering, DestripeMethod::kLarge,
                           DestripeMethod::kDead, DestripeMethod::kAll}) {
    if (name == destripe_method_name(m)) return m;
  }
  throw InputError("a destripe method is normalise, sorting, filtering, large, dead or all (got \"" +
                   std::string(name) + "\")");
}

const char* destripe_method_name(DestripeMethod method) {
  switch (method) {
    case DestripeMethod::kNormalise: return "normalise";
    case DestripeMethod::kSorting: return "sorting";
    case DestripeMethod::kFiltering: return "filtering";
    case DestripeMethod::kLarge: return "large";
    case DestripeMethod::kDead: return "dead";
    case DestripeMethod::kAll: return "all";
  }
  return "?";
}

Array destripe(const Array& measurement, const Geometry& g, const DestripeOptions& options,
               DestripeReport* report) {
  g.validate();
  g.check_measurement_shape(measurement.shape);
  const std::size_t views = g.n_views(), columns = g.n_u, rows = g.is_3d() ? g.n_v : 1;
  if (views < 8 || columns < 8) {
    throw InputError("stripe removal needs at least 8 views and 8 columns (the scan has " +
                     std::to_string(views) + " x " + std::to_string(columns) + ")");
  }
  if (!(options.snr > 0.0) || !(options.sigma > 0.0)) {
    throw InputError("destripe: snr and sigma must be positive");
  }
  const std::size_t size = window(options.size, kSmallWindow, columns);
  const std::size_t large_size = window(options.large_size, kLargeWindow, columns);
  // The device outlives the op that holds its context.
  std::optional<Device> opened;
  std::unique_ptr<ops::StripeSortingOp> device;
  const bool sorts = options.method == DestripeMethod::kSorting ||
                     options.method == DestripeMethod::kFiltering ||
                     options.method == DestripeMethod::kAll;
  if (options.engine == Engine::kOpenCL && sorts) {
    opened = options.device ? *options.device : Device::open();
    cl::Context& context = cl::context_of(*opened);
    if (ops::StripeSortingOp::supported(context, views, size)) {
      device = std::make_unique<ops::StripeSortingOp>(context, views, columns);
    }
  }
  Array out = measurement;
  DestripeReport local;
  local.non_finite_replaced = analytic::repair_non_finite(out, columns);
  local.removed = Array({rows, columns});
  local.size = size;
  local.large_size = large_size;
  for (std::size_t r = 0; r < rows; ++r) {
    Sinogram s{views, columns, std::vector<double>(views * columns)};
    for (std::size_t v = 0; v < views; ++v) {
      for (std::size_t c = 0; c < columns; ++c) s.at(v, c) = out.data[(v * rows + r) * columns + c];
    }
    const Sinogram before = s;
    std::vector<bool> dead, large;
    switch (options.method) {
      case DestripeMethod::kNormalise: normalise(s, size); break;
      case DestripeMethod::kSorting: sorting(s, size, device.get()); break;
      case DestripeMethod::kFiltering: filtering(s, size, options.sigma, device.get()); break;
      case DestripeMethod::kLarge:
        large = large_stripes(s, large_size, options.snr, options.drop_ratio);
        break;
      case DestripeMethod::kDead: dead = dead_stripes(s, large_size, options.snr); break;
      case DestripeMethod::kAll:
        dead = dead_stripes(s, large_size, options.snr);
        large = large_stripes(s, large_size, options.snr, options.drop_ratio);
        sorting(s, size, device.get());
        break;
    }
    for (std::size_t c = 0; c < columns; ++c) {
      if (c < dead.size() && dead[c]) local.dead.push_back(r * columns + c);
      if (c < large.size() && large[c]) local.large.push_back(r * columns + c);
      double removed = 0.0;
      for (std::size_t v = 0; v < views; ++v) removed += before.at(v, c) - s.at(v, c);
      local.removed.data[r * columns + c] = static_cast<float>(removed / static_cast<double>(views));
    }
    for (std::size_t v = 0; v < views; ++v) {
      for (std::size_t c = 0; c < columns; ++c) {
        out.data[(v * rows + r) * columns + c] = static_cast<float>(s.at(v, c));
      }
    }
  }
  if (report != nullptr) *report = std::move(local);
  return out;
}

}  // namespace riner
