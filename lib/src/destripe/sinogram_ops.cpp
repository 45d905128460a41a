#include "destripe/sinogram_ops.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "util/parallel.hpp"

namespace riner::stripes {

std::size_t reflect(long i, std::size_t n) {
  const long m = static_cast<long>(n);
  if (i < 0) i = -i - 1;
  if (i >= m) i = 2 * m - i - 1;
  return static_cast<std::size_t>(std::clamp(i, 0L, m - 1));
}

SortedColumns sort_columns(const Sinogram& s) {
  SortedColumns out;
  out.sorted = s;
  out.view.assign(s.values.size(), 0);
  util::parallel_for(s.columns, [&](std::size_t begin, std::size_t end) {
    std::vector<std::size_t> order(s.views);
    for (std::size_t c = begin; c < end; ++c) {
      std::iota(order.begin(), order.end(), 0);
      // Stable, so equal readings keep their view order and the result is deterministic.
      std::stable_sort(order.begin(), order.end(),
                       [&](std::size_t a, std::size_t b) { return s.at(a, c) < s.at(b, c); });
      for (std::size_t k = 0; k < s.views; ++k) {
        out.sorted.at(k, c) = s.at(order[k], c);
        out.view[k * s.columns + c] = order[k];
      }
    }
  });
  return out;
}

Sinogram unsort_columns(const Sinogram& sorted, const std::vector<std::size_t>& view) {
  Sinogram out = sorted;
  for (std::size_t k = 0; k < sorted.views; ++k) {
    for (std::size_t c = 0; c < sorted.columns; ++c) {
      out.at(view[k * sorted.columns + c], c) = sorted.at(k, c);
    }
  }
  return out;
}

std::vector<double> median_filter(const std::vector<double>& values, std::size_t size) {
  const std::size_t n = values.size();
  const long half = static_cast<long>(size / 2);
  std::vector<double> out(n), window(size);
  for (std::size_t c = 0; c < n; ++c) {
    for (long d = -half; d <= half; ++d) {
      window[static_cast<std::size_t>(d + half)] = values[reflect(static_cast<long>(c) + d, n)];
    }
    std::nth_element(window.begin(), window.begin() + half, window.end());
    out[c] = window[static_cast<std::size_t>(half)];
  }
  return out;
}

Sinogram median_across_columns(const Sinogram& s, std::size_t size) {
  Sinogram out = s;
  util::parallel_for(s.views, [&](std::size_t begin, std::size_t end) {
    std::vector<double> row(s.columns);
    for (std::size_t v = begin; v < end; ++v) {
      std::copy_n(s.values.begin() + static_cast<long>(v * s.columns), s.columns, row.begin());
      const std::vector<double> filtered = median_filter(row, size);
      std::copy(filtered.begin(), filtered.end(),
                out.values.begin() + static_cast<long>(v * s.columns));
    }
  });
  return out;
}

Sinogram smooth_along_ranks(const Sinogram& sorted, const Sinogram& filtered, std::size_t window) {
  Sinogram out = sorted;
  const long n = static_cast<long>(sorted.views), reach = static_cast<long>(window / 2);
  const auto correction = [&](long k, std::size_t c) {
    const auto at = static_cast<std::size_t>(k);
    return filtered.at(at, c) - sorted.at(at, c);
  };
  for (std::size_t c = 0; c < sorted.columns; ++c) {
    double sum = 0.0;
    for (long k = 0; k <= std::min(reach, n - 1); ++k) sum += correction(k, c);
    for (long k = 0; k < n; ++k) {
      const long first = std::max(k - reach, 0L), last = std::min(k + reach, n - 1);
      out.at(static_cast<std::size_t>(k), c) += sum / static_cast<double>(last - first + 1);
      if (k + reach + 1 < n) sum += correction(k + reach + 1, c);
      if (k - reach >= 0) sum -= correction(k - reach, c);
    }
  }
  return out;
}

std::vector<bool> detect_stripes(const std::vector<double>& values, double snr,
                                 const std::vector<bool>* allowed) {
  const std::size_t n = values.size();
  std::vector<bool> mask(n, false);
  if (n < 8) return mask;
  std::vector<double> sorted = values;
  std::sort(sorted.begin(), sorted.end());
  // A line through the sorted profile's middle half: its rise over the whole profile is the
  // noise level; stripes are the ends that leave it by snr times that.
  const std::size_t drop = n / 4;
  double sx = 0, sy = 0, sxx = 0, sxy = 0, m = 0;
  for (std::size_t i = drop; i + drop + 1 < n; ++i) {
    const double x = static_cast<double>(i);
    sx += x;
    sy += sorted[i];
    sxx += x * x;
    sxy += x * sorted[i];
    m += 1.0;
  }
  const double slope = (m * sxy - sx * sy) / std::max(1e-300, m * sxx - sx * sx);
  const double intercept = (sy - slope * sx) / m;
  const double y_end = intercept + slope * static_cast<double>(n - 1);
  const double noise = std::max(1e-6, std::fabs(y_end - intercept));
  if (std::fabs(sorted.back() - y_end) / noise >= snr) {
    const double upper = y_end + 0.5 * snr * noise;
    for (std::size_t i = 0; i < n; ++i) mask[i] = mask[i] || values[i] > upper;
  }
  if (std::fabs(intercept - sorted.front()) / noise >= snr) {
    const double lower = intercept - 0.5 * snr * noise;
    for (std::size_t i = 0; i < n; ++i) mask[i] = mask[i] || values[i] <= lower;
  }
  if (allowed != nullptr) {
    for (std::size_t i = 0; i < n; ++i) mask[i] = mask[i] && (*allowed)[i];
  }
  std::vector<bool> grown = mask;
  for (std::size_t i = 0; i < n; ++i) {
    if (!mask[i]) continue;
    if (i > 0) grown[i - 1] = true;
    if (i + 1 < n) grown[i + 1] = true;
  }
  return grown;
}

ColumnInterpolation interpolation_plan(const std::vector<bool>& mask) {
  const std::size_t columns = mask.size();
  ColumnInterpolation plan{std::vector<std::size_t>(columns), std::vector<std::size_t>(columns),
                           std::vector<double>(columns, -1.0)};
  std::vector<std::size_t> kept;
  for (std::size_t c = 0; c < columns; ++c) {
    plan.left[c] = plan.right[c] = c;
    if (!mask[c]) kept.push_back(c);
  }
  if (kept.empty() || kept.size() == columns) return plan;
  for (std::size_t c = 0; c < columns; ++c) {
    if (!mask[c]) continue;
    const auto next = std::lower_bound(kept.begin(), kept.end(), c);
    if (next == kept.begin()) {
      plan.left[c] = plan.right[c] = *next;
      plan.weight[c] = 0.0;
    } else if (next == kept.end()) {
      plan.left[c] = plan.right[c] = kept.back();
      plan.weight[c] = 0.0;
    } else {
      plan.left[c] = *(next - 1);
      plan.right[c] = *next;
      plan.weight[c] = static_cast<double>(c - plan.left[c]) / static_cast<double>(*next - plan.left[c]);
    }
  }
  return plan;
}

void interpolate_columns(Sinogram& s, const ColumnInterpolation& plan) {
  for (std::size_t c = 0; c < s.columns; ++c) {
    const double t = plan.weight[c];
    if (t < 0.0) continue;
    for (std::size_t v = 0; v < s.views; ++v) {
      s.at(v, c) = (1.0 - t) * s.at(v, plan.left[c]) + t * s.at(v, plan.right[c]);
    }
  }
}

namespace {

// The raised-cosine weight of the far end at step j + 1 of a blend of n steps.
double blend_weight(std::size_t j, std::size_t n) {
  return 0.5 - 0.5 * std::cos(M_PI * static_cast<double>(j + 1) / static_cast<double>(n + 1));
}

}  // namespace

Sinogram periodic_extension(const Sinogram& s, std::size_t views, std::size_t columns) {
  Sinogram out{views, columns, std::vector<double>(views * columns, 0.0)};
  const std::size_t extra_columns = columns - s.columns, extra_views = views - s.views;
  for (std::size_t v = 0; v < s.views; ++v) {
    for (std::size_t c = 0; c < s.columns; ++c) out.at(v, c) = s.at(v, c);
    const double last = s.at(v, s.columns - 1), first = s.at(v, 0);
    for (std::size_t j = 0; j < extra_columns; ++j) {
      const double w = blend_weight(j, extra_columns);
      out.at(v, s.columns + j) = (1.0 - w) * last + w * first;
    }
  }
  for (std::size_t j = 0; j < extra_views; ++j) {
    const double w = blend_weight(j, extra_views);
    for (std::size_t c = 0; c < columns; ++c) {
      out.at(s.views + j, c) = (1.0 - w) * out.at(s.views - 1, c) + w * out.at(0, c);
    }
  }
  return out;
}

Sinogram crop(const Sinogram& padded, std::size_t views, std::size_t columns) {
  Sinogram out{views, columns, std::vector<double>(views * columns)};
  for (std::size_t v = 0; v < views; ++v) {
    for (std::size_t c = 0; c < columns; ++c) out.at(v, c) = padded.at(v, c);
  }
  return out;
}

}  // namespace riner::stripes
