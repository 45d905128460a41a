#include "preprocessing/centre_sinogram.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <unsupported/Eigen/FFT>
#include <vector>

#include "analytic/fbp_setup.hpp"
#include "riner/centre.hpp"
#include "util/parallel.hpp"
#include "util/robust_statistics.hpp"

namespace riner::preprocessing {

namespace {

// The coarse search's sinogram: at most this many columns and views (binned).
constexpr std::size_t kCoarseColumns = 256;
constexpr std::size_t kMostViews = 256;
// The spectral measure's best stands where it is this close to the filled measure's (px).
constexpr double kAgreePx = 0.5;
// The coarse search's measure takes a transform per candidate: fewer views.
constexpr std::size_t kCoarseViews = 128;
// The fine search at full width: this step (px) within one coarse column of the coarse minimum.
constexpr double kFineStepPx = 0.25;
constexpr std::size_t kMostRows = 8;
// The stripes' check (stripes_dominate): the stripes' part of a column's mean is its difference
// from the median of the columns within this many on either side.
constexpr std::size_t kStripeNeighbours = 2;
// object_columns: a column the object reaches spreads over its views by more than this share of
// the most any column does; air lies beyond them by this many columns at both ends.
constexpr double kObjectSpreadShare = 0.1;
constexpr std::size_t kAirMarginColumns = 2;
// Angles evenly spaced within this share of the step.
constexpr double kEvenSpacing = 0.1;
// The half-turn may end this many steps short of pi (a 179.5-degree scan of 180 views ends
// 1.5 steps and a hair short), but no more than kMostGapRad unless within 1.5 steps (a coarse
// scan's missing 60 degrees is no half-turn).
constexpr double kMostGapSteps = 4.0;
constexpr double kMostGapRad = 4.0 * M_PI / 180.0;

using Row = std::vector<double>;

// The next length >= n whose only prime factors are 2, 3 and 5 (fast FFTs).
std::size_t smooth_length(std::size_t n) {
  for (std::size_t m = n;; ++m) {
    std::size_t r = m;
    for (std::size_t p : {2, 3, 5}) {
      while (r % p == 0) r /= p;
    }
    if (r == 1) return m;
  }
}

// A half-turn sinogram [views][columns] binned by `by_views` and `by_columns` (means), then
// resampled in angle (linearly, over the half-turn) to a view count whose FFT is fast: the
// column transforms run over twice the views, and 229 (neutron360's half-turn) is prime.
std::vector<Row> binned(const std::vector<Row>& s, std::size_t by_views, std::size_t by_columns) {
  const std::size_t views = s.size() / by_views, columns = s[0].size() / by_columns;
  std::vector<Row> bins(views, Row(columns, 0.0));
  for (std::size_t v = 0; v < views * by_views; ++v) {
    for (std::size_t u = 0; u < columns * by_columns; ++u) {
      bins[v / by_views][u / by_columns] += s[v][u];
    }
  }
  const double n = static_cast<double>(by_views * by_columns);
  for (Row& r : bins) {
    for (double& x : r) x /= n;
  }
  const std::size_t count = smooth_length(views);
  if (count == views) return bins;
  std::vector<Row> out(count, Row(columns));
  for (std::size_t i = 0; i < count; ++i) {
    const double x =
        static_cast<double>(i) * static_cast<double>(views - 1) / static_cast<double>(count - 1);
    const auto k = std::min(static_cast<std::size_t>(x), views - 2);
    const double t = x - static_cast<double>(k);
    for (std::size_t u = 0; u < columns; ++u)
      out[i][u] = (1.0 - t) * bins[k][u] + t * bins[k + 1][u];
  }
  return out;
}

// A row's spectrum, padded to `padded` by a straight line from its last value back to its
// first (no step at the wrap).
std::vector<std::complex<double>> padded_spectrum(const Row& r, std::size_t padded) {
  const std::size_t n = r.size();
  Row line(padded);
  std::copy(r.begin(), r.end(), line.begin());
  const std::size_t gap = padded - n;
  for (std::size_t i = 0; i < gap; ++i) {
    const double t = static_cast<double>(i + 1) / static_cast<double>(gap + 1);
    line[n + i] = (1.0 - t) * r.back() + t * r.front();
  }
  Eigen::FFT<double> fft;
  std::vector<std::complex<double>> out;
  fft.fwd(out, line);
  return out;
}

// The harmonics m (of a full turn of `turn` views) outside the double wedge at detector
// frequency k (of a row padded to `padded` from `n` columns): harmonic m of a point at radius r
// (px) has |m| <= 2 pi r k / padded, and r reaches half the detector. Empty past the last k
// with any.
std::vector<std::size_t> outside_wedge(std::size_t k, std::size_t n, std::size_t padded,
                                       std::size_t turn) {
  const double slope = M_PI * static_cast<double>(n) / static_cast<double>(padded);
  const double wedge = slope * static_cast<double>(k) + 1.0;
  std::vector<std::size_t> outside;
  if (wedge >= 0.5 * static_cast<double>(turn)) return outside;
  for (std::size_t m = 0; m < turn; ++m) {
    const double signed_m =
        m <= turn / 2 ? static_cast<double>(m) : static_cast<double>(m) - static_cast<double>(turn);
    if (std::fabs(signed_m) > wedge) outside.push_back(m);
  }
  return outside;
}

// Mean magnitude of the stacked sinogram's spectrum outside the double wedge: the first half's
// rows as they are, the second half's mirrored about `axis`. The mirror is taken in the rows'
// spectra (r(2a - u) has the spectrum exp(-4 pi i k a / P) conj(R(k)) for a row of period P):
// exact at any fractional axis, where linear interpolation would damp the high frequencies
// more at some fractions than at others and pull the minimum towards them. The transform over
// the views is linear, so each frequency's two halves are transformed once, here, and a
// candidate axis costs one complex multiply-add per harmonic instead of a transform.
class WedgeEnergy {
 public:
  explicit WedgeEnergy(const std::vector<Row>& s)
      : n_(s[0].size()), padded_(smooth_length(2 * s[0].size())), views_(s.size()) {
    std::vector<std::vector<std::complex<double>>> rows;
    for (const Row& r : s) rows.push_back(padded_spectrum(r, padded_));
    const std::size_t turn = 2 * views_;
    Eigen::FFT<double> fft;
    std::vector<std::complex<double>> column(turn), harmonics;
    for (std::size_t k = 1; k <= padded_ / 2; ++k) {
      const std::vector<std::size_t> outside = outside_wedge(k, n_, padded_, turn);
      if (outside.empty()) break;
      Frequency f;
      f.k = static_cast<double>(k);
      std::fill(column.begin(), column.end(), std::complex<double>{});
      for (std::size_t v = 0; v < views_; ++v) column[v] = rows[v][k];
      fft.fwd(harmonics, column);
      for (std::size_t m : outside) f.first.push_back(harmonics[m]);
      std::fill(column.begin(), column.end(), std::complex<double>{});
      for (std::size_t v = 0; v < views_; ++v) column[views_ + v] = std::conj(rows[v][k]);
      fft.fwd(harmonics, column);
      for (std::size_t m : outside) f.mirrored.push_back(harmonics[m]);
      count_ += static_cast<double>(outside.size());
      frequencies_.push_back(std::move(f));
    }
  }

  double operator()(double axis) const {
    double sum = 0.0;
    for (const Frequency& f : frequencies_) {
      const std::complex<double> shift =
          std::polar(1.0, -4.0 * M_PI * f.k * axis / static_cast<double>(padded_));
      for (std::size_t i = 0; i < f.first.size(); ++i) {
        // |z| as sqrt(norm): std::abs's overflow-safe hypot is several times slower.
        sum += std::sqrt(std::norm(f.first[i] + shift * f.mirrored[i]));
      }
    }
    return count_ > 0.0 ? sum / count_ : 0.0;
  }

 private:
  // One detector frequency's harmonics outside the wedge, of the first half-turn alone and of
  // the mirrored second half alone (before its shift).
  struct Frequency {
    double k = 0.0;
    std::vector<std::complex<double>> first, mirrored;
  };

  std::size_t n_ = 0;
  std::size_t padded_ = 0;
  std::size_t views_ = 0;
  double count_ = 0.0;
  std::vector<Frequency> frequencies_;
};

// The same measure with the mirrored half built in real space, where the columns its mirror
// image does not reach hold the first half-turn in reverse view order (as Vo's own code fills
// them). An object wider than the field of view reads non-zero at the detector's ends; in the
// spectral mirror those columns meet the padding's wrap, whose seam costs less the larger the
// shift, and the search can end at its edge (a 200-column scan of a wider object, the axis 30 px
// off: -50.75). Filled, the columns no mirror reaches continue the first half without a seam
// at every axis (the search's best within a few tenths of a pixel of the axis where a wide
// object biases the spectral measure by a pixel or more). One row transform per view and
// candidate: the coarse search's measure.
class FilledWedgeEnergy {
 public:
  explicit FilledWedgeEnergy(const std::vector<Row>& s)
      : rows_(s), n_(s[0].size()), padded_(smooth_length(2 * s[0].size())), views_(s.size()) {
    const std::size_t turn = 2 * views_;
    Eigen::FFT<double> fft;
    std::vector<std::vector<std::complex<double>>> spectra;
    for (const Row& r : s) spectra.push_back(padded_spectrum(r, padded_));
    std::vector<std::complex<double>> column(turn), harmonics;
    for (std::size_t k = 1; k <= padded_ / 2; ++k) {
      std::vector<std::size_t> outside = outside_wedge(k, n_, padded_, turn);
      if (outside.empty()) break;
      std::fill(column.begin(), column.end(), std::complex<double>{});
      for (std::size_t v = 0; v < views_; ++v) column[v] = spectra[v][k];
      fft.fwd(harmonics, column);
      std::vector<std::complex<double>> first;
      for (std::size_t m : outside) first.push_back(harmonics[m]);
      count_ += static_cast<double>(outside.size());
      outside_.push_back(std::move(outside));
      first_.push_back(std::move(first));
    }
  }

  double operator()(double axis) const {
    const std::size_t turn = 2 * views_;
    const std::size_t frequencies = first_.size();
    // The mirrored half's spectra at the frequencies used, view by view.
    std::vector<std::vector<std::complex<double>>> spectra(views_);
    Eigen::FFT<double> fft;
    Row mirrored(n_);
    for (std::size_t v = 0; v < views_; ++v) {
      const Row& r = rows_[v];
      const Row& reverse = rows_[views_ - 1 - v];
      for (std::size_t j = 0; j < n_; ++j) {
        const double x = 2.0 * axis - static_cast<double>(j);
        if (x < 0.0 || x > static_cast<double>(n_ - 1)) {
          mirrored[j] = reverse[j];
          continue;
        }
        const auto i = std::min(static_cast<std::size_t>(x), n_ - 2);
        const double t = x - static_cast<double>(i);
        mirrored[j] = (1.0 - t) * r[i] + t * r[i + 1];
      }
      spectra[v] = padded_spectrum(mirrored, padded_);
    }
    std::vector<std::complex<double>> column(turn), harmonics;
    double sum = 0.0;
    for (std::size_t f = 0; f < frequencies; ++f) {
      std::fill(column.begin(), column.end(), std::complex<double>{});
      for (std::size_t v = 0; v < views_; ++v) column[views_ + v] = spectra[v][f + 1];
      fft.fwd(harmonics, column);
      for (std::size_t i = 0; i < outside_[f].size(); ++i) {
        sum += std::sqrt(std::norm(first_[f][i] + harmonics[outside_[f][i]]));
      }
    }
    return count_ > 0.0 ? sum / count_ : 0.0;
  }

 private:
  std::vector<Row> rows_;
  std::size_t n_ = 0;
  std::size_t padded_ = 0;
  std::size_t views_ = 0;
  double count_ = 0.0;
  // Per detector frequency k = 1, 2, ...: the harmonics outside the wedge, and the first
  // half's share of them.
  std::vector<std::vector<std::size_t>> outside_;
  std::vector<std::vector<std::complex<double>>> first_;
};

// The best of `candidates` (evaluated in parallel; the costs of every half-turn added) and its
// neighbours' costs.
struct Minimum {
  std::size_t index = 0;
  std::vector<double> costs;
};
template <typename Cost>
Minimum minimise(const std::vector<Cost>& costs, const std::vector<double>& candidates) {
  Minimum m;
  m.costs.resize(candidates.size());
  util::parallel_for(candidates.size(), [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      m.costs[i] = 0.0;
      for (const Cost& cost : costs) m.costs[i] += cost(candidates[i]);
    }
  });
  m.index =
      static_cast<std::size_t>(std::min_element(m.costs.begin(), m.costs.end()) - m.costs.begin());
  return m;
}

// A parabola's vertex through the best of `m` and its neighbours, on candidates `step` apart.
double vertex(const Minimum& m, const std::vector<double>& candidates, double step) {
  if (m.index == 0 || m.index + 1 == candidates.size()) return candidates[m.index];
  const double y0 = m.costs[m.index - 1], y1 = m.costs[m.index], y2 = m.costs[m.index + 1];
  const double curvature = y0 - 2.0 * y1 + y2;
  const double shift = curvature > 0.0 ? 0.5 * (y0 - y2) / curvature : 0.0;
  return candidates[m.index] + std::clamp(shift, -0.5, 0.5) * step;
}

// The columns the object reaches in a half-turn: each column's spread over the views (2nd to
// 98th percentile: a stripe, constant over the views, has none) above kObjectSpreadShare of
// the largest; nullopt unless air (kAirMarginColumns or more) lies beyond them at both ends of
// the detector (an object wider than the field of view, or noise near the object's spread).
// The object half a turn later lies at the columns' mirror image about the axis, on the
// detector too: candidates whose mirror sends it off the detector are no axis. The filled
// measure is small there (the columns no mirror reaches hold the half-turn reversed, seamless),
// and a 10-column object 6.25 px off the middle of 160 columns, noise-free, ended the search
// at its end.
std::optional<std::pair<double, double>> object_columns(
    const std::vector<std::vector<Row>>& turns) {
  const std::size_t n = turns[0][0].size();
  std::vector<double> spread(n, 0.0), column;
  for (const std::vector<Row>& s : turns) {
    for (std::size_t u = 0; u < n; ++u) {
      column.clear();
      for (const Row& r : s) column.push_back(r[u]);
      const double low = util::quantile(column, 0.02), high = util::quantile(column, 0.98);
      spread[u] = std::max(spread[u], high - low);
    }
  }
  const double largest = *std::max_element(spread.begin(), spread.end());
  if (!(largest > 0.0)) return std::nullopt;
  std::size_t first = n, last = 0;
  for (std::size_t u = 0; u < n; ++u) {
    if (spread[u] > kObjectSpreadShare * largest) first = std::min(first, u), last = u;
  }
  if (first < kAirMarginColumns || last + kAirMarginColumns > n - 1) return std::nullopt;
  return std::pair{static_cast<double>(first), static_cast<double>(last)};
}

// The axis of one detector row from its half-turn sinograms (one per half-turn the scan holds;
// finite values); nullopt where the coarse search's best is at the end of its range (no
// minimum found: the true axis lies beyond, or the measure failed).
std::optional<double> row_axis(const std::vector<std::vector<Row>>& turns) {
  const std::size_t n = turns[0][0].size();
  const std::size_t by_views = std::max<std::size_t>(1, turns[0].size() / kMostViews);
  const std::size_t by_coarse_views = (turns[0].size() + kCoarseViews - 1) / kCoarseViews;
  const std::size_t by_columns = (n + kCoarseColumns - 1) / kCoarseColumns;
  std::vector<FilledWedgeEnergy> coarse;
  std::vector<WedgeEnergy> wide;
  for (const std::vector<Row>& s : turns) {
    coarse.emplace_back(binned(s, by_coarse_views, by_columns));
    wide.emplace_back(binned(s, by_views, 1));
  }
  const double nb = static_cast<double>(n / by_columns);
  double low = (0.5 - kCentreSearchShare) * (nb - 1.0),
         high = (0.5 + kCentreSearchShare) * (nb - 1.0);
  if (const auto object = object_columns(turns)) {
    // Binned column a covers columns by_columns a .. by_columns (a + 1) - 1.
    const double f = static_cast<double>(by_columns);
    const auto binned_column = [&](double c) { return (c - 0.5 * (f - 1.0)) / f; };
    low = std::max(low, binned_column(0.5 * object->second));
    high = std::min(high, binned_column(0.5 * (object->first + static_cast<double>(n - 1))));
  }
  std::vector<double> candidates;
  for (double a = low; a <= high + 1e-9; a += 0.5) candidates.push_back(a);
  if (candidates.size() < 3) return std::nullopt;
  const Minimum c = minimise(coarse, candidates);
  if (c.index == 0 || c.index + 1 == candidates.size()) return std::nullopt;
  // Binned column a covers columns by_columns a .. by_columns (a + 1) - 1.
  const double f = static_cast<double>(by_columns);
  const double centre = f * candidates[c.index] + 0.5 * (f - 1.0);
  std::vector<double> fine;
  for (double a = centre - f; a <= centre + f + 1e-9; a += kFineStepPx) fine.push_back(a);
  const Minimum m = minimise(wide, fine);
  // The spectral measure's best where it has one inside its window near the filled one's (a
  // few hundredths of a pixel where the object is within the field of view); else the filled.
  const double coarse_axis = f * vertex(c, candidates, 0.5) + 0.5 * (f - 1.0);
  if (m.index > 0 && m.index + 1 < fine.size()) {
    const double fine_axis = vertex(m, fine, kFineStepPx);
    if (std::fabs(fine_axis - coarse_axis) <= std::max(kAgreePx, 0.5 * f)) return fine_axis;
  }
  return coarse_axis;
}

// Each column's mean over a half-turn's views.
Row column_means(const std::vector<Row>& s) {
  Row mean(s[0].size(), 0.0);
  for (const Row& r : s) {
    for (std::size_t u = 0; u < r.size(); ++u) mean[u] += r[u];
  }
  for (double& m : mean) m /= static_cast<double>(s.size());
  return mean;
}

// Each column less its mean over the half-turn. A stripe (an element's offset, constant over the
// views) is then gone from both the half-turn and its mirror image; left in, its mirror image
// breaks the stacked turn at every seam as a wrong axis does, and on an object narrow against
// the detector those breaks outweigh the object's (a 12-column object among 160 ringed
// columns: 28.85 px off, the stripes' own axis). The object's half-turn mean is not symmetric
// about the axis (a half-turn sees it from one side), so the measure then leans by a few
// tenths of a pixel (0.22 px on that object's clean scan), so only where the stripes dominate.
std::vector<std::vector<Row>> without_column_means(std::vector<std::vector<Row>> turns) {
  for (std::vector<Row>& s : turns) {
    const Row mean = column_means(s);
    for (Row& r : s) {
      for (std::size_t u = 0; u < r.size(); ++u) r[u] -= mean[u];
    }
  }
  return turns;
}

// Whether the stripes (each column mean's departure from its neighbours' median) carry more
// energy than the object's change over the views (each column's spread about its mean): the
// stripes' mirror images then decide the measure.
bool stripes_dominate(const std::vector<std::vector<Row>>& turns) {
  double stripes = 0.0, object = 0.0;
  for (const std::vector<Row>& s : turns) {
    const std::size_t n = s[0].size();
    const Row mean = column_means(s);
    for (const Row& r : s) {
      for (std::size_t u = 0; u < n; ++u) {
        object += (r[u] - mean[u]) * (r[u] - mean[u]) / static_cast<double>(s.size());
      }
    }
    std::vector<double> around;
    for (std::size_t u = 0; u < n; ++u) {
      around.clear();
      for (std::size_t j = u >= kStripeNeighbours ? u - kStripeNeighbours : 0;
           j <= std::min(n - 1, u + kStripeNeighbours); ++j) {
        around.push_back(mean[j]);
      }
      const double d = mean[u] - util::quantile(around, 0.5);
      stripes += d * d;
    }
  }
  return stripes > object;
}

// The row's axis: from the readings without their column means where the stripes dominate
// (on ringed scans of faint objects: 3.48 px for 3.5 and -7.26 for -7.25 where the readings as
// they are said 2.87 and -6.98; a 12-column object's 2.2-39.2 px astray to 0.22), else from the
// readings as they are.
std::optional<double> row_axis_past_stripes(const std::vector<std::vector<Row>>& turns) {
  if (!stripes_dominate(turns)) return row_axis(turns);
  const std::optional<double> centred = row_axis(without_column_means(turns));
  return centred ? centred : row_axis(turns);
}

// The scan's half-turns of evenly spaced views: the first view of each (the second starts at
// the first view half a turn after the first's); empty when not even the first fits.
std::vector<std::size_t> half_turns(const std::vector<double>& angles, std::size_t* views) {
  const double step = std::fabs(angles[1] - angles[0]);
  if (!(step > 0.0)) return {};
  std::vector<std::size_t> starts;
  std::size_t start = 0;
  while (start + 2 < angles.size()) {
    std::size_t end = start + 1;
    while (end < angles.size() && std::fabs(angles[end] - angles[start]) < M_PI - 0.5 * step) {
      if (std::fabs(std::fabs(angles[end] - angles[end - 1]) - step) > kEvenSpacing * step) {
        return starts;
      }
      ++end;
    }
    const double gap = std::max(1.5 * step, std::min(kMostGapSteps * step, kMostGapRad));
    if (std::fabs(angles[end - 1] - angles[start]) < M_PI - gap) return starts;
    if (starts.empty()) *views = end - start;
    if (end - start != *views) return starts;
    starts.push_back(start);
    start = end;
  }
  return starts;
}

}  // namespace

std::optional<SinogramAxis> sinogram_axis(const Scan& scan) {
  const Geometry& g = scan.geometry;
  if (g.is_divergent() || g.n_views() < 8 || g.n_u < 8) return std::nullopt;
  std::size_t views = 0;
  const std::vector<std::size_t> starts = half_turns(g.angles, &views);
  if (starts.empty()) return std::nullopt;
  // Rows evenly spread (all of a 2D scan's one).
  const std::size_t rows = g.is_3d() ? g.n_v : 1;
  const std::size_t used = std::min(rows, kMostRows);
  Array half({views, g.n_u});
  std::vector<double> axes;
  for (std::size_t i = 0; i < used; ++i) {
    const std::size_t row = (2 * i + 1) * rows / (2 * used);
    std::vector<std::vector<Row>> turns;
    for (std::size_t start : starts) {
      for (std::size_t v = 0; v < views; ++v) {
        const float* line = scan.measurement.ptr() + ((start + v) * rows + row) * g.n_u;
        std::copy(line, line + g.n_u, half.data.begin() + static_cast<long>(v * g.n_u));
      }
      analytic::repair_non_finite(half, g.n_u);
      std::vector<Row>& s = turns.emplace_back(views, Row(g.n_u));
      for (std::size_t v = 0; v < views; ++v) {
        std::copy_n(half.data.begin() + static_cast<long>(v * g.n_u), g.n_u, s[v].begin());
      }
    }
    if (const std::optional<double> axis = row_axis_past_stripes(turns)) axes.push_back(*axis);
  }
  if (axes.empty()) return SinogramAxis{std::numeric_limits<double>::quiet_NaN(), views, 0};
  return SinogramAxis{util::quantile(axes, 0.5), views * starts.size(), axes.size()};
}

}  // namespace riner::preprocessing
