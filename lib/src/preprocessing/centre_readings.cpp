#include "preprocessing/centre_readings.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "model/noise_evidence.hpp"
#include "model/stuck_elements.hpp"
#include "riner/rays.hpp"

namespace riner::preprocessing {

namespace {

// A hot or dead element reading a steady value matches its own mirror image only about itself,
// and pulls the axis onto it (a 180-degree scan with one column at 50: the axis at that
// column): such elements are left out, as non-finite ones are. The scan itself where none is.
Scan without_stuck(const Scan& scan) {
  const std::vector<std::uint8_t> stuck =
      model::stuck_elements(scan, model::reading_noise(scan).sigma);
  if (std::find(stuck.begin(), stuck.end(), 1) == stuck.end()) return scan;
  Scan without = scan;
  std::vector<float>& rho = without.measurement.data;
  for (std::size_t e = 0; e < stuck.size(); ++e) {
    if (!stuck[e]) continue;
    for (std::size_t i = e; i < rho.size(); i += stuck.size()) rho[i] = NAN;
  }
  without.non_finite = compute_stats(without.measurement).non_finite();
  return without;
}

// Spikes (riner/scan.hpp's largest_reading) left out as unread readings are: five readings of
// 1e5 among readings of 3 moved a fan scan's axis 12 px.
Scan without_spikes(Scan scan) {
  mark_corrupt_readings(scan.measurement, scan.geometry.n_views());
  return scan;
}

// Each detector element's readings less their mean over a full turn. A stripe (an element's
// offset, constant over the views) then reads 0, where a conjugate reading, on another element,
// differs from it by the two elements' offsets at every candidate axis: on ringed scans of a
// faint object (line integrals up to 1.5, responses +-25%) the conjugate rays put a fan's axis
// 1.7 px off, a cone's 1.9, and a parallel half acquisition's on the wrong side (+27.8 px for
// -45). Over a full turn an element and its conjugate see the same lines, so their means agree
// about the true axis: the object's matching is unchanged (those scans: 0.00 px off).
Scan without_element_means(Scan scan) {
  const std::size_t views = scan.geometry.n_views();
  const std::size_t per_view = scan.measurement.size() / views;
  std::vector<double> sum(per_view, 0.0);
  std::vector<std::size_t> count(per_view, 0);
  const std::vector<float>& rho = scan.measurement.data;
  for (std::size_t i = 0; i < rho.size(); ++i) {
    if (std::isfinite(rho[i])) sum[i % per_view] += rho[i], ++count[i % per_view];
  }
  for (std::size_t i = 0; i < rho.size(); ++i) {
    const std::size_t e = i % per_view;
    if (count[e] > 0) scan.measurement.data[i] -= static_cast<float>(sum[e] / count[e]);
  }
  return scan;
}

}  // namespace

bool holds_structure(const Array& measurement) {
  const ArrayStats stats = compute_stats(measurement);
  return stats.max > stats.min;
}

// The row through z = 0, read between the two rows around it.
Scan midplane_fan(const Scan& cone) {
  const Geometry& g = cone.geometry;
  const double v = std::clamp(project_to_detector(g, 0, Vec3{0.0, 0.0, 0.0}).v, 0.0,
                              static_cast<double>(g.n_v - 1));
  const auto r0 = std::min(static_cast<std::size_t>(v), g.n_v > 1 ? g.n_v - 2 : 0);
  const std::size_t r1 = std::min(r0 + 1, g.n_v - 1);
  const double w = v - static_cast<double>(r0);
  Scan fan;
  fan.geometry = g;
  fan.geometry.type = GeometryType::kFan2d;
  fan.geometry.n_v = 1;
  fan.geometry.offset_v = 0.0;
  fan.geometry.volume_shape = {g.volume_shape[1], g.volume_shape[2]};
  const std::size_t views = g.n_views(), n_u = g.n_u;
  fan.measurement = Array({views, n_u});
  for (std::size_t a = 0; a < views; ++a) {
    const float* row0 = cone.measurement.ptr() + (a * g.n_v + r0) * n_u;
    const float* row1 = cone.measurement.ptr() + (a * g.n_v + r1) * n_u;
    for (std::size_t e = 0; e < n_u; ++e) {
      fan.measurement.data[a * n_u + e] = static_cast<float>((1.0 - w) * row0[e] + w * row1[e]);
    }
  }
  return fan;
}

// A shuffled or interleaved acquisition: the conjugate rays are read between neighbouring views.
// A scan that turns back over its own angles has them twice: the methods need each angle once,
// evenly spaced. A view is left out where its angle repeats its neighbour's exactly, or where
// it lies within a quarter of the gaps on either side of the pair and a quarter of the views
// or more do so (a way back whose encoder reads its angles a little differently); views at
// random angles (a ninth of their gaps so small) or a few clustered ones keep every view.
Scan in_angle_order(Scan scan) {
  const std::vector<double>& a = scan.geometry.angles;
  const std::size_t n = a.size();
  if (n < 2) return scan;
  std::vector<std::size_t> order(n);
  for (std::size_t i = 0; i < n; ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t x, std::size_t y) { return a[x] < a[y]; });
  std::vector<double> gap(n - 1);
  for (std::size_t i = 0; i + 1 < n; ++i) gap[i] = a[order[i + 1]] - a[order[i]];
  std::vector<char> exact(n - 1, 0), near(n - 1, 0);
  std::size_t nears = 0;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    exact[i] = gap[i] <= 1e-9 * std::max(1.0, std::fabs(a[order[i]]));
    double beside = std::numeric_limits<double>::infinity();
    if (i > 0) beside = std::min(beside, gap[i - 1]);
    if (i + 2 < n) beside = std::min(beside, gap[i + 1]);
    near[i] = std::isfinite(beside) && gap[i] < 0.25 * beside;
    nears += near[i] || exact[i];
  }
  const bool repeats = 4 * nears >= n - 1;
  std::vector<std::size_t> kept{order.front()};
  for (std::size_t i = 0; i + 1 < n; ++i) {
    if (!(exact[i] || (repeats && near[i]))) kept.push_back(order[i + 1]);
  }
  const bool rising = std::is_sorted(a.begin(), a.end());
  const bool falling = std::is_sorted(a.rbegin(), a.rend());
  if ((rising || falling) && kept.size() == n) return scan;
  const std::size_t per_view = scan.measurement.size() / n;
  std::vector<std::size_t> shape = scan.measurement.shape;
  shape[0] = kept.size();
  Scan sorted;
  sorted.geometry = scan.geometry;
  sorted.geometry.uniform_angles.reset();
  sorted.geometry.angles.resize(kept.size());
  sorted.measurement = Array(shape);
  for (std::size_t i = 0; i < kept.size(); ++i) {
    sorted.geometry.angles[i] = a[kept[i]];
    std::copy_n(scan.measurement.ptr() + kept[i] * per_view, per_view,
                sorted.measurement.ptr() + i * per_view);
  }
  sorted.non_finite = compute_stats(sorted.measurement).non_finite();
  return sorted;
}

bool source_plane_on_detector(const Geometry& cone) {
  const double v = project_to_detector(cone, 0, Vec3{0.0, 0.0, 0.0}).v;
  return v >= -0.5 && v <= static_cast<double>(cone.n_v) - 0.5;
}

Scan centre_rows(const Scan& scan) {
  const Geometry& g = scan.geometry;
  const std::size_t views = g.n_views(), n_u = g.n_u;
  std::vector<std::size_t> rows;
  Scan cut;
  if (g.type == GeometryType::kCone3d) {
    const double v = std::clamp(project_to_detector(g, 0, Vec3{0.0, 0.0, 0.0}).v, 0.0,
                                static_cast<double>(g.n_v - 1));
    const std::size_t first =
        std::min(static_cast<std::size_t>(std::max(0.0, v - 1.0)), g.n_v > 4 ? g.n_v - 4 : 0);
    const std::size_t count = std::min<std::size_t>(4, g.n_v);
    for (std::size_t r = first; r < first + count; ++r) rows.push_back(r);
    cut.geometry = detector_rows_geometry(g, first, count);
  } else {
    const std::size_t count = std::min(kCentreRows, g.n_v);
    for (std::size_t i = 0; i < count; ++i) rows.push_back(i * g.n_v / count);
    cut.geometry = g;
    cut.geometry.n_v = rows.size();
  }
  cut.measurement = Array({views, rows.size(), n_u});
  for (std::size_t a = 0; a < views; ++a) {
    for (std::size_t i = 0; i < rows.size(); ++i) {
      std::copy_n(scan.measurement.ptr() + (a * g.n_v + rows[i]) * n_u, n_u,
                  cut.measurement.ptr() + (a * rows.size() + i) * n_u);
    }
  }
  cut.non_finite = compute_stats(cut.measurement).non_finite();
  return cut;
}

Scan compared(Scan scan) {
  return covers_full_turn(scan.geometry) ? without_element_means(std::move(scan)) : scan;
}

Scan prepared(const Scan& scan) {
  const bool cut = scan.geometry.is_3d() && scan.measurement.size() > kMostCopiedReadings;
  return without_spikes(without_stuck(cut ? centre_rows(scan) : scan));
}

Scan compared_fan(const Scan& scan) {
  Scan fan = compared(prepared(scan));
  if (scan.geometry.type == GeometryType::kCone3d) fan = midplane_fan(fan);
  return in_angle_order(std::move(fan));
}

}  // namespace riner::preprocessing
