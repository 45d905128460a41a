#include "analytic/fbp_setup.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numeric>
#include <unsupported/Eigen/FFT>
#include <vector>

#include "riner/rays.hpp"
#include "util/fill_between.hpp"

namespace riner::analytic {

std::size_t repair_non_finite(Array& measurement, std::size_t n_u, std::size_t rows) {
  std::size_t replaced = 0;
  const std::size_t lines = measurement.size() / n_u;
  std::vector<bool> empty(lines, false);
  const float largest = largest_reading(measurement, lines / std::max<std::size_t>(rows, 1));
  for (std::size_t line = 0; line < lines; ++line) {
    float* p = measurement.ptr() + line * n_u;
    long previous = -1;  // last finite index
    empty[line] = true;
    for (std::size_t j = 0; j <= n_u; ++j) {
      if (j < n_u && !(std::fabs(p[j]) <= largest)) continue;  // NaN fails it too
      // Fill the gap (previous, j) from its finite ends.
      for (std::size_t k = static_cast<std::size_t>(previous + 1); k < j; ++k) {
        float value = 0.0f;
        if (previous >= 0 && j < n_u) {
          const float w = static_cast<float>(k - previous) / static_cast<float>(j - previous);
          value = (1.0f - w) * p[previous] + w * p[j];
        } else if (previous >= 0) {
          value = p[previous];
        } else if (j < n_u) {
          value = p[j];
        }
        p[k] = value;
        ++replaced;
      }
      previous = static_cast<long>(j);
      empty[line] = empty[line] && j == n_u;
    }
  }
  // A line with nothing finite (a dead detector row, a lost view) read as 0 is air where the
  // object is: it takes the rows beside it in its view, then, for a view with none, the views
  // beside it.
  rows = std::max<std::size_t>(rows, 1);
  const std::size_t views = lines / rows;
  std::vector<bool> view_empty(views, false);
  for (std::size_t v = 0; v < views; ++v) {
    std::vector<bool> row_empty(empty.begin() + static_cast<std::ptrdiff_t>(v * rows),
                                empty.begin() + static_cast<std::ptrdiff_t>((v + 1) * rows));
    view_empty[v] = !util::fill_between(measurement.ptr() + v * rows * n_u, n_u, n_u, row_empty);
  }
  util::fill_between(measurement.ptr(), rows * n_u, rows * n_u, view_empty);
  return replaced;
}

void cosine_weight(Array& measurement, const Geometry& g) {
  if (!g.is_divergent()) return;
  const double sdd = g.source_origin_mm + g.origin_detector_mm;
  const std::size_t rows = g.is_3d() ? g.n_v : 1;
  std::vector<float> weight(rows * g.n_u);
  for (std::size_t r = 0; r < rows; ++r) {
    const double v = g.is_3d() ? (r - 0.5 * (g.n_v - 1.0) + g.offset_v) * g.pitch_v : 0.0;
    for (std::size_t j = 0; j < g.n_u; ++j) {
      const double u = (j - 0.5 * (g.n_u - 1.0) + g.offset_u) * g.pitch_u;
      weight[r * g.n_u + j] = static_cast<float>(sdd / std::sqrt(sdd * sdd + u * u + v * v));
    }
  }
  for (std::size_t i = 0; i < measurement.size(); ++i)
    measurement.data[i] *= weight[i % weight.size()];
}

double extend_half_acquisition(Array& measurement, Geometry& g) {
  if (g.n_u < 2 || !covers_full_turn(g)) return 0.0;
  const std::vector<double> d = column_ray_distances(g);
  const auto [low, high] = std::minmax_element(d.begin(), d.end());
  if (!(*low < 0.0 && *high > 0.0)) return 0.0;
  const double overlap = std::min(-*low, *high);
  const double far = std::max(-*low, *high);
  if (overlap >= kHalfAcquisitionShare * far) return 0.0;
  const double side = *high > -*low ? 1.0 : -1.0;  // the far side's sign
  const std::size_t n = g.n_u;
  std::vector<float> weight(n);
  for (std::size_t j = 0; j < n; ++j) {
    const double t = side * d[j];  // -overlap .. far
    const double s = std::sin(0.25 * M_PI * (std::min(t, overlap) + overlap) / overlap);
    weight[j] = static_cast<float>(2.0 * s * s);
  }
  // Columns to add on the near end: as many as the far side has beyond the overlap.
  const bool near_first = std::fabs(d.front()) < std::fabs(d.back());
  std::size_t beyond = 0;
  for (double v : d) beyond += side * v > overlap;
  const std::size_t lines = measurement.size() / n;
  std::vector<std::size_t> shape = measurement.shape;
  shape.back() = n + beyond;
  Array wide(shape, 0.0f);
  const std::size_t start = near_first ? beyond : 0;
  for (std::size_t line = 0; line < lines; ++line) {
    for (std::size_t j = 0; j < n; ++j) {
      wide.data[line * (n + beyond) + start + j] = measurement.data[line * n + j] * weight[j];
    }
  }
  measurement = std::move(wide);
  // Element j keeps its place: (j' - (n' - 1) / 2 + offset') = (j - (n - 1) / 2 + offset).
  const double half = 0.5 * static_cast<double>(beyond);
  g.offset_u += near_first ? -half : half;
  g.n_u = n + beyond;
  return overlap;
}

double filter_spacing(const Geometry& g) {
  if (!g.is_divergent()) return g.pitch_u;
  return g.pitch_u * g.source_origin_mm / (g.source_origin_mm + g.origin_detector_mm);
}

std::vector<double> filter_taps(std::size_t n_u, double tau, FbpFilter filter) {
  std::size_t padded = 1;
  while (padded < 2 * n_u) padded *= 2;
  // The spatial Ram-Lak kernel on the circular grid: h(0) = 1/(4 tau^2), h(odd k) =
  // -1/(pi k tau)^2, h(even k) = 0.
  std::vector<double> h(padded, 0.0);
  for (std::size_t m = 0; m < padded; ++m) {
    const long k =
        m <= padded / 2 ? static_cast<long>(m) : static_cast<long>(m) - static_cast<long>(padded);
    if (k == 0) {
      h[m] = 1.0 / (4.0 * tau * tau);
    } else if (k % 2 != 0) {
      h[m] = -1.0 / (M_PI * M_PI * static_cast<double>(k * k) * tau * tau);
    }
  }
  if (filter != FbpFilter::kRamLak) {
    Eigen::FFT<double> fft;
    std::vector<std::complex<double>> spectrum;
    fft.fwd(spectrum, h);
    for (std::size_t m = 0; m < padded; ++m) {
      const double f =
          (m <= padded / 2 ? static_cast<double>(m) : static_cast<double>(m) - padded) /
          static_cast<double>(padded);  // cycles per sample, |f| <= 1/2
      double window = 1.0;
      if (filter == FbpFilter::kSheppLogan) {
        window = f == 0.0 ? 1.0 : std::sin(M_PI * f) / (M_PI * f);
      } else {
        window = 0.5 * (1.0 + std::cos(2.0 * M_PI * f));
      }
      spectrum[m] *= window;
    }
    fft.inv(h, spectrum);
  }
  std::vector<double> taps(2 * n_u - 1);
  for (long k = -static_cast<long>(n_u - 1); k <= static_cast<long>(n_u - 1); ++k) {
    const std::size_t m =
        static_cast<std::size_t>((k + static_cast<long>(padded)) % static_cast<long>(padded));
    taps[static_cast<std::size_t>(k + static_cast<long>(n_u) - 1)] = h[m] * tau;
  }
  return taps;
}

std::vector<double> view_weights(const Geometry& g, bool* short_scan) {
  const std::size_t n = g.n_views();
  const double period = g.is_divergent() ? 2.0 * M_PI : M_PI;
  std::vector<double> phase(n);
  for (std::size_t i = 0; i < n; ++i) {
    phase[i] = std::fmod(g.angles[i], period);
    if (phase[i] < 0.0) phase[i] += period;
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return phase[a] < phase[b]; });
  // Views at one phase (a second turn, a repeated angle) form a group that shares its weight
  // equally; each group owns half the gap to each neighbouring group, cyclically: the shares
  // sum to the period. (Before, a 720-degree scan's views paired up: half weighed nothing and
  // the gaps between pairs, twice the mean step, read as a short scan.)
  const double same = 1e-9 * period;
  std::vector<std::size_t> group_start;  // positions in `order` where a group begins
  for (std::size_t s = 0; s < n; ++s) {
    if (s == 0 || phase[order[s]] - phase[order[s - 1]] > same) group_start.push_back(s);
  }
  const std::size_t groups = group_start.size();
  if (groups > 1 && phase[order[0]] + period - phase[order[n - 1]] <= same) {
    // The last group wraps onto the first (phases just below the period and 0).
    group_start.erase(group_start.begin());
  }
  const std::size_t m = group_start.size();
  std::vector<double> weights(n, period);
  double largest_gap = 0.0;
  if (m > 1) {
    std::vector<double> gaps(m);
    for (std::size_t k = 0; k < m; ++k) {
      const double here = phase[order[group_start[k]]];
      double next = phase[order[group_start[(k + 1) % m]]];
      if (next <= here) next += period;
      gaps[k] = next - here;
      largest_gap = std::max(largest_gap, gaps[k]);
    }
    for (std::size_t k = 0; k < m; ++k) {
      const std::size_t begin = group_start[k], end = group_start[(k + 1) % m];
      const std::size_t size = (end + n - begin - 1) % n + 1;
      const double share = 0.5 * (gaps[k] + gaps[(k + m - 1) % m]) / static_cast<double>(size);
      for (std::size_t j = 0; j < size; ++j) weights[order[(begin + j) % n]] = share;
    }
  } else {
    for (double& w : weights) w = period / static_cast<double>(n);
  }
  if (short_scan != nullptr) {
    // A gap several times the mean step between distinct views: part of the circle unseen.
    *short_scan = m <= 1 || largest_gap > 3.0 * period / static_cast<double>(m);
  }
  const double scale = g.is_divergent() ? 0.5 : 1.0;
  for (double& w : weights) w *= scale;
  return weights;
}

namespace {

// The fan angle of each detector column's ray at view 0 in Parker's sense: its conjugate ray
// leaves from the source position pi + 2 gamma further along the scan. From the geometry's own
// rays (the second crossing of the column's line with the source circle), so the detector's
// orientation and the direction of rotation need no convention here.
std::vector<double> conjugate_fan_angles(const Geometry& g, double direction) {
  const double mid_row = g.is_3d() ? 0.5 * (static_cast<double>(g.n_v) - 1.0) : 0.0;
  std::vector<double> gamma(g.n_u);
  for (std::size_t j = 0; j < g.n_u; ++j) {
    const Ray ray = detector_ray(g, 0, static_cast<double>(j), mid_row);
    const Vec3& s = ray.origin;
    // In the axial plane: |s + t d| = |s| again at t = -2 (s . d) / |d|^2.
    const double dx = ray.direction.x, dy = ray.direction.y;
    const double t = -2.0 * (s.x * dx + s.y * dy) / (dx * dx + dy * dy);
    const double a0 = std::atan2(s.y, s.x);
    const double a1 = std::atan2(s.y + t * dy, s.x + t * dx);
    double turn = std::fmod(direction * (a1 - a0), 2.0 * M_PI);
    if (turn < 0.0) turn += 2.0 * M_PI;
    gamma[j] = 0.5 * (turn - M_PI);
  }
  return gamma;
}

}  // namespace

std::optional<ParkerSpan> parker_span(const Geometry& g) {
  const std::size_t n = g.n_views();
  if (!g.is_divergent() || n < 3) return std::nullopt;
  // Evenly stepping views, in either direction.
  const double step = (g.angles[n - 1] - g.angles[0]) / static_cast<double>(n - 1);
  for (std::size_t i = 1; i < n; ++i) {
    if (std::fabs(g.angles[i] - g.angles[i - 1] - step) > 0.1 * std::fabs(step)) {
      return std::nullopt;
    }
  }
  const double last = std::fabs(step) * static_cast<double>(n - 1);  // the last view's beta
  if (last + std::fabs(step) >= 2.0 * M_PI - 0.5 * std::fabs(step)) return std::nullopt;  // a turn
  // Which way the source moves as beta grows, from the first two views' sources.
  const Vec3 s0 = detector_ray(g, 0, 0.0).origin, s1 = detector_ray(g, 1, 0.0).origin;
  const double moved = std::remainder(std::atan2(s1.y, s1.x) - std::atan2(s0.y, s0.x), 2.0 * M_PI);
  ParkerSpan span;
  span.step = std::fabs(step);
  span.gamma = conjugate_fan_angles(g, moved >= 0.0 ? 1.0 : -1.0);
  double fan = 0.0;  // the largest |gamma|
  for (double v : span.gamma) fan = std::max(fan, std::fabs(v));
  span.delta = 0.5 * (last - M_PI);                  // Parker's half fan, stretched to the range
  if (span.delta < fan - 1e-9) return std::nullopt;  // lines the scan never measured
  return span;
}

bool views_miss_lines(const Geometry& g) {
  bool short_scan = false;
  (void)view_weights(g, &short_scan);
  return short_scan && !parker_span(g);
}

bool parker_weight(Array& measurement, const Geometry& g, std::vector<double>& view_weights) {
  const std::optional<ParkerSpan> span = parker_span(g);
  if (!span) return false;
  const std::size_t n = g.n_views();
  const double delta = span->delta, step = span->step;
  const std::vector<double>& gamma = span->gamma;
  const std::size_t rows = g.is_3d() ? g.n_v : 1;
  const auto weight = [&](double beta, double gam) {
    if (beta < 2.0 * (delta - gam)) {
      const double s = std::sin(0.25 * M_PI * beta / (delta - gam));
      return s * s;
    }
    if (beta <= M_PI - 2.0 * gam) return 1.0;
    const double s = std::sin(0.25 * M_PI * (M_PI + 2.0 * delta - beta) / (delta + gam));
    return beta <= M_PI + 2.0 * delta ? s * s : 0.0;
  };
  for (std::size_t i = 0; i < n; ++i) {
    const double beta = step * static_cast<double>(i);
    for (std::size_t r = 0; r < rows; ++r) {
      float* line = measurement.ptr() + (i * rows + r) * g.n_u;
      for (std::size_t j = 0; j < g.n_u; ++j) {
        line[j] = static_cast<float>(line[j] * weight(beta, gamma[j]));
      }
    }
  }
  view_weights.assign(n, step);
  return true;
}

}  // namespace riner::analytic
