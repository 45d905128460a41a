#include "riner/flat_field.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "riner/error.hpp"
#include "riner/io.hpp"
#include "util/robust_statistics.hpp"

namespace riner {

namespace {

// Per-pixel mean over the finite values of a frame or a stack of frames shaped like one view
// (only the frames `members` lists, when given); NaN where no frame is finite.
std::vector<double> frame_mean(const Array& frames, const std::vector<std::size_t>& view_shape,
                               const char* what, std::size_t* frame_count,
                               const std::vector<std::size_t>* members = nullptr) {
  const std::size_t pixels = shape_size(view_shape);
  std::vector<std::size_t> one_frame_shape = frames.shape;
  std::size_t count = 1;
  if (frames.rank() == view_shape.size() + 1) {
    count = frames.shape[0];
    one_frame_shape.erase(one_frame_shape.begin());
  }
  if (one_frame_shape != view_shape || count == 0) {
    throw InputError(std::string(what) + " is " + shape_string(frames.shape) +
                     "; it must be one frame of a view's shape " + shape_string(view_shape) +
                     " or a stack of them");
  }
  if (members) count = members->size();
  std::vector<double> sum(pixels, 0.0);
  std::vector<std::size_t> finite(pixels, 0);
  for (std::size_t m = 0; m < count; ++m) {
    const float* frame = frames.ptr() + (members ? (*members)[m] : m) * pixels;
    for (std::size_t p = 0; p < pixels; ++p) {
      if (std::isfinite(frame[p])) {
        sum[p] += frame[p];
        ++finite[p];
      }
    }
  }
  for (std::size_t p = 0; p < pixels; ++p) {
    sum[p] = finite[p] ? sum[p] / static_cast<double>(finite[p])
                       : std::numeric_limits<double>::quiet_NaN();
  }
  *frame_count = count;
  return sum;
}

// The flat frames taken at one position (their indices), in order of position; one series of
// every frame when no positions are given.
struct FlatSeries {
  double position = 0.0;
  std::vector<std::size_t> members;  // empty: every frame
};

std::vector<FlatSeries> flat_series(const Array& flats, const std::vector<double>& positions,
                                    const std::vector<std::size_t>& view_shape) {
  if (positions.empty()) return {{0.0, {}}};
  const bool stack = flats.rank() == view_shape.size() + 1;
  const std::size_t frames = stack ? flats.shape[0] : 1;
  if (positions.size() != frames) {
    throw InputError(std::to_string(positions.size()) + " flat positions for " +
                     std::to_string(frames) + " flat frames");
  }
  std::vector<double> distinct = positions;
  std::sort(distinct.begin(), distinct.end());
  distinct.erase(std::unique(distinct.begin(), distinct.end()), distinct.end());
  std::vector<FlatSeries> out;
  for (double at : distinct) {
    FlatSeries s{at, {}};
    for (std::size_t f = 0; f < frames; ++f) {
      if (positions[f] == at) s.members.push_back(f);
    }
    out.push_back(std::move(s));
  }
  return out;
}

double median_of(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), mid, values.end());
  return *mid;
}

// The dark field's noise from frame to frame, one figure per detector row (a slab's rows get
// the figures a whole stack's would: the estimate does not depend on how a scan is cut): each
// pixel's variance over its finite frames, averaged over the row's pixels but those above
// kHotPixelVariance times the row's median (hot or flickering pixels). Each frame's offset
// along the row (its median departure from the mean dark) is taken out first: a dark level that
// drifts from frame to frame is no noise of a reading. Zeros with fewer than two frames: one
// frame, or frames averaged before they were saved, say nothing of the noise.
constexpr double kHotPixelVariance = 25.0;
std::vector<double> dark_noise_by_row(const Array& darks,
                                      const std::vector<std::size_t>& view_shape,
                                      const std::vector<double>& dark) {
  const std::size_t pixels = shape_size(view_shape);
  const std::size_t columns = view_shape.back();
  const std::size_t rows = pixels / columns;
  std::vector<double> sigma(rows, 0.0);
  if (darks.rank() != view_shape.size() + 1 || darks.shape[0] < 2) return sigma;
  const std::size_t frames = darks.shape[0];
  std::vector<double> variance(columns);
  std::vector<double> offset(frames);
  for (std::size_t row = 0; row < rows; ++row) {
    for (std::size_t f = 0; f < frames; ++f) {
      std::vector<double> departures;
      for (std::size_t c = 0; c < columns; ++c) {
        const float x = darks.data[f * pixels + row * columns + c];
        if (std::isfinite(x)) departures.push_back(x - dark[row * columns + c]);
      }
      offset[f] = departures.empty() ? 0.0 : median_of(std::move(departures));
    }
    std::size_t n_pixels = 0;
    for (std::size_t c = 0; c < columns; ++c) {
      const std::size_t p = row * columns + c;
      double mean = 0.0;
      std::size_t n = 0;
      for (std::size_t f = 0; f < frames; ++f) {
        const float x = darks.data[f * pixels + p];
        if (std::isfinite(x)) {
          mean += x - offset[f];
          ++n;
        }
      }
      if (n >= 2) mean /= static_cast<double>(n);
      double sum = 0.0;
      for (std::size_t f = 0; f < frames; ++f) {
        const float x = darks.data[f * pixels + p];
        if (std::isfinite(x)) sum += (x - offset[f] - mean) * (x - offset[f] - mean);
      }
      if (n >= 2) variance[n_pixels++] = sum / static_cast<double>(n - 1);
    }
    if (n_pixels == 0) continue;
    const double typical = median_of(std::vector<double>(
        variance.begin(), variance.begin() + static_cast<std::ptrdiff_t>(n_pixels)));
    double sum = 0.0;
    std::size_t n = 0;
    for (std::size_t i = 0; i < n_pixels; ++i) {
      if (variance[i] <= kHotPixelVariance * typical) {
        sum += variance[i];
        ++n;
      }
    }
    sigma[row] = n ? std::sqrt(sum / static_cast<double>(n)) : 0.0;
  }
  return sigma;
}

}  // namespace

bool air_drifts(const FlatFieldReport& r) {
  return std::isfinite(r.air_first) && std::isfinite(r.air_last) &&
         std::min(std::fabs(r.air_first), std::fabs(r.air_last)) <= kAirDriftLevelMost &&
         r.air_drift_sigmas > kAirDriftSigmas &&
         std::fabs(r.air_last - r.air_first) > kAirDriftLeast;
}

std::string air_drift_line(const FlatFieldReport& r) {
  if (!air_drifts(r)) return "";
  char line[400];
  std::snprintf(line, sizeof(line),
                "note: the air reads %.4f in the first tenth of the views and %.4f in the last "
                "(%.1f%% %s light, %.0f times its noise): the beam or the detector drifted "
                "during the scan, and a flat field from one time leaves rings and bands; %s",
                r.air_first, r.air_last, 100.0 * std::fabs(std::expm1(r.air_first - r.air_last)),
                r.air_last > r.air_first ? "less" : "more", r.air_drift_sigmas,
                r.flat_series > 1 ? "the flats before and after did not follow it (check them)"
                                  : "give flats from after the scan too (--flat-after)");
  return line;
}

std::string air_level_line(const FlatFieldReport& r) {
  if (!std::isfinite(r.air_first) || !std::isfinite(r.air_last)) return "";
  const double level = std::min(r.air_first, r.air_last);
  char line[400];
  if (level < -kAirBelowZero) {
    std::snprintf(line, sizeof(line),
                  "note: the air reads %.3f after the flat field, where it reads 0: the "
                  "projections saw %.0f%% more light than the flat field; check that the flat "
                  "and dark fields are of this scan's exposure, gain and scale",
                  level, 100.0 * std::expm1(-level));
    return line;
  }
  if (level > kAirAbove) {
    std::snprintf(line, sizeof(line),
                  "note: even the least-attenuated elements read %.2f after the flat field "
                  "(under %.1f%% of the beam): were the readings -ln(I/I0) already, or is the "
                  "flat field of another detector region or exposure?",
                  level, 100.0 * std::exp(-level));
    return line;
  }
  return "";
}

std::string saturation_line(const FlatFieldReport& r) {
  if (r.saturated_readings == 0) return "";
  return "note: " + std::to_string(r.saturated_readings) +
         " readings at their type's largest count (a saturated detector: more light than it "
         "counts) taken as invalid";
}

std::size_t mark_saturated(Array& projections, const std::string& dtype) {
  const float most = dtype == "uint16" ? 65535.0f : dtype == "uint8" ? 255.0f : 0.0f;
  if (most == 0.0f) return 0;
  std::size_t count = 0;
  for (float& x : projections.data) {
    if (x == most) {
      x = std::numeric_limits<float>::quiet_NaN();
      ++count;
    }
  }
  return count;
}

std::string pixels_without_beam_line(const FlatFieldReport& r) {
  const double share =
      r.pixels > 0 ? static_cast<double>(r.pixels_without_beam) / static_cast<double>(r.pixels)
                   : 0.0;
  if (share <= kMostPixelsWithoutBeam) return "";
  char line[400];
  std::snprintf(
      line, sizeof(line),
      "note: %zu of the detector's %zu pixels (%.1f%%) have no beam in the flat field (at "
      "or below the dark): riner takes them for dead elements; check that the flat and "
      "dark fields are of this detector's region, binning and exposure",
      r.pixels_without_beam, r.pixels, 100.0 * share);
  return line;
}

void flat_field_drift(const Array& rho, FlatFieldReport& r) {
  r.air_first = r.air_last = std::numeric_limits<double>::quiet_NaN();
  r.air_drift_sigmas = 0.0;
  if (rho.rank() < 2 || rho.shape[0] < 20) return;
  const std::size_t views = rho.shape[0];
  const std::size_t pixels = rho.size() / views;
  // Air: the elements that read least over the scan (each element's median over the views),
  // among at most kDriftPixels of them spread over the detector (a stack's frames are large).
  constexpr std::size_t kDriftPixels = 4096;
  const std::size_t stride = std::max<std::size_t>(1, pixels / kDriftPixels);
  std::vector<std::pair<double, std::size_t>> level;
  std::vector<double> column(views);
  for (std::size_t p = 0; p < pixels; p += stride) {
    std::size_t n = 0;
    for (std::size_t v = 0; v < views; ++v) {
      const float x = rho.data[v * pixels + p];
      if (std::isfinite(x)) column[n++] = x;
    }
    if (n * 2 < views) continue;
    level.push_back({median_of(std::vector<double>(column.begin(), column.begin() + n)), p});
  }
  if (level.size() < 3) return;
  std::sort(level.begin(), level.end());
  const std::size_t air = std::max<std::size_t>(3, level.size() / 20);
  // The air's mean reading per view.
  std::vector<double> per_view(views, 0.0);
  for (std::size_t v = 0; v < views; ++v) {
    double sum = 0.0;
    std::size_t n = 0;
    for (std::size_t a = 0; a < air; ++a) {
      const float x = rho.data[v * pixels + level[a].second];
      if (std::isfinite(x)) {
        sum += x;
        ++n;
      }
    }
    per_view[v] = n ? sum / static_cast<double>(n) : std::numeric_limits<double>::quiet_NaN();
  }
  // Its noise from view to view (differences of neighbours: a slow drift does not enter).
  std::vector<double> steps;
  for (std::size_t v = 1; v < views; ++v) {
    if (std::isfinite(per_view[v]) && std::isfinite(per_view[v - 1])) {
      steps.push_back(std::fabs(per_view[v] - per_view[v - 1]));
    }
  }
  const double sigma = util::kMadToSigma * median_of(steps) / std::sqrt(2.0);
  const std::size_t tenth = std::max<std::size_t>(2, views / 10);
  auto mean_of = [&](std::size_t first) {
    double sum = 0.0;
    std::size_t n = 0;
    for (std::size_t v = first; v < first + tenth; ++v) {
      if (std::isfinite(per_view[v])) {
        sum += per_view[v];
        ++n;
      }
    }
    return n ? sum / static_cast<double>(n) : std::numeric_limits<double>::quiet_NaN();
  };
  r.air_first = mean_of(0);
  r.air_last = mean_of(views - tenth);
  const double error = sigma * std::sqrt(2.0 / static_cast<double>(tenth));
  r.air_drift_sigmas = error > 0.0 ? std::fabs(r.air_last - r.air_first) / error
                                   : (r.air_last != r.air_first ? 1e9 : 0.0);
}

Array flat_field_normalise(const Array& projections, const Array& flats, const Array& darks,
                           FlatFieldReport* report, const std::vector<double>& flat_positions) {
  if (projections.rank() != 2 && projections.rank() != 3) {
    throw InputError("projections are " + shape_string(projections.shape) +
                     "; expected [views, elements] or [views, rows, columns]");
  }
  const std::vector<std::size_t> view_shape(projections.shape.begin() + 1, projections.shape.end());
  const std::size_t pixels = shape_size(view_shape);
  FlatFieldReport r;
  std::vector<double> dark(pixels, 0.0);
  std::vector<double> no_light(pixels, 0.0);  // light at or below this is none
  if (!darks.shape.empty()) {
    dark = frame_mean(darks, view_shape, "the dark field", &r.dark_frames);
    const std::vector<double> sigma = dark_noise_by_row(darks, view_shape, dark);
    const std::size_t columns = view_shape.back();
    const double mean_error = std::sqrt(1.0 + 1.0 / static_cast<double>(r.dark_frames));
    for (std::size_t p = 0; p < pixels; ++p) {
      no_light[p] = kDarkNoiseSigmas * sigma[p / columns] * mean_error;
    }
    r.dark_noise = median_of(sigma);
  }
  // Each series' beam F - D per pixel, NaN where there is none (in any series).
  const std::vector<FlatSeries> series = flat_series(flats, flat_positions, view_shape);
  std::vector<std::vector<double>> beams;
  std::vector<char> no_beam(pixels, 0);
  for (const FlatSeries& s : series) {
    std::size_t frames = 0;
    std::vector<double> beam = frame_mean(flats, view_shape, "the flat field", &frames,
                                          s.members.empty() ? nullptr : &s.members);
    r.flat_frames += frames;
    for (std::size_t p = 0; p < pixels; ++p) {
      beam[p] -= dark[p];
      if (!(beam[p] > 0.0)) no_beam[p] = 1;
    }
    beams.push_back(std::move(beam));
  }
  r.flat_series = series.size();
  for (std::size_t p = 0; p < pixels; ++p) r.pixels_without_beam += no_beam[p];
  // Where the beam stands less than kDarkNoiseLeastDepth above the noise (a dim beam, a low-flux
  // neutron or lab scan, the edge of a beam's profile), light within the noise is a thick
  // body's, which its readings still tell on average: only light at or below the dark is none.
  for (std::size_t p = 0; p < pixels; ++p) {
    if (!(beams.front()[p] >= std::exp(kDarkNoiseLeastDepth) * no_light[p])) no_light[p] = 0.0;
  }
  r.pixels = pixels;
  if (beams.size() > 1) {
    std::vector<double> change;
    for (std::size_t p = 0; p < pixels; ++p) {
      if (!no_beam[p]) change.push_back(beams.back()[p] / beams.front()[p] - 1.0);
    }
    r.flat_change = change.empty() ? 0.0 : median_of(change);
  }
  Array rho(projections.shape);
  const std::size_t views = projections.shape[0];
  for (std::size_t v = 0; v < views; ++v) {
    // This view's beam: between the series either side of it.
    const double at = static_cast<double>(v);
    std::size_t hi = 0;
    while (hi < series.size() && series[hi].position < at) ++hi;
    const std::size_t lo = hi == 0 ? 0 : hi - 1;
    hi = std::min(hi, series.size() - 1);
    const double span = series[hi].position - series[lo].position;
    const double w = span > 0.0 ? (at - series[lo].position) / span : 0.0;
    for (std::size_t p = 0; p < pixels; ++p) {
      const std::size_t i = v * pixels + p;
      const double light = static_cast<double>(projections.data[i]) - dark[p];
      if (!(light > no_light[p]) || no_beam[p]) {
        // No light left (within the dark's noise) under a beam: -ln 0, a beam the object stopped
        // or a dead pixel, which model/starved_readings.hpp tells apart. Light within the noise
        // says only that the ray's line integral is large: its logarithm would be noise (a
        // count over the dark reads 9 where the next reads 7) and break a metal's trace into
        // pieces read as dead elements.
        const bool dark_only = !no_beam[p] && !std::isnan(light);
        if (dark_only && light > 0.0) ++r.readings_in_dark_noise;
        rho.data[i] = dark_only ? std::numeric_limits<float>::infinity()
                                : std::numeric_limits<float>::quiet_NaN();
        ++r.invalid_readings;
        continue;
      }
      const double beam = (1.0 - w) * beams[lo][p] + w * beams[hi][p];
      rho.data[i] = static_cast<float>(-std::log(light / beam));
    }
  }
  if (r.invalid_readings == rho.size()) {
    throw InputError(
        "no projection reading is above its dark field under a flat field above "
        "its dark: check the flat and dark files");
  }
  flat_field_drift(rho, r);
  if (report) *report = r;
  return rho;
}

FlatStack flats_before_after(const Array& before, const Array& after,
                             const std::vector<std::size_t>& projections_shape) {
  if (after.shape.empty()) return {before, {}};
  const std::size_t view_rank = projections_shape.size() - 1;
  auto frames_of = [&](const Array& a) { return a.rank() == view_rank + 1 ? a.shape[0] : 1; };
  auto frame_shape = [&](const Array& a) {
    return std::vector<std::size_t>(a.shape.end() - static_cast<std::ptrdiff_t>(
                                                        std::min(view_rank, a.rank())),
                                    a.shape.end());
  };
  const std::vector<std::size_t> view = frame_shape(before);
  if (view != frame_shape(after) || after.rank() < view_rank || after.rank() > view_rank + 1) {
    throw InputError("the flats after the scan are " + shape_string(after.shape) +
                     ", the flats before " + shape_string(before.shape) +
                     ": they must be frames of one shape");
  }
  const std::size_t views = projections_shape[0];
  const std::size_t n_before = frames_of(before);
  const std::size_t n_after = frames_of(after);
  std::vector<std::size_t> shape = view;
  shape.insert(shape.begin(), n_before + n_after);
  FlatStack out{Array(shape), {}};
  std::copy(before.data.begin(), before.data.end(), out.frames.data.begin());
  std::copy(after.data.begin(), after.data.end(),
            out.frames.data.begin() + static_cast<std::ptrdiff_t>(before.size()));
  out.positions.assign(n_before, -0.5);
  out.positions.resize(n_before + n_after, static_cast<double>(views) - 0.5);
  return out;
}

Scan raw_scan(Geometry geometry, const Array& projections, const Array& flats, const Array& darks,
              std::optional<std::size_t> row, const std::string& what, FlatFieldReport* report,
              const std::vector<double>& flat_positions) {
  Scan scan;
  scan.geometry = std::move(geometry);
  if (row) require_slice_geometry(scan.geometry);
  FlatFieldReport r;
  try {
    if (row) {
      // The projections first: their rows are what the user asked for.
      const Array projection_row = detector_row(projections, *row);
      // A field's frames must be the views' frames (one frame, or a stack) before a row of
      // them is taken: a row of the wrong frames would pass unnoticed.
      const auto field_row = [&](const Array& frames, const char* field) {
        Array stack = frames;
        if (stack.rank() == 2) stack.shape.insert(stack.shape.begin(), 1);
        if (stack.rank() != 3 || stack.shape[1] != projections.shape[1] ||
            stack.shape[2] != projections.shape[2]) {
          throw InputError(std::string(field) + " is " + shape_string(frames.shape) +
                           "; it must be one frame of a view's shape " +
                           shape_string({projections.shape[1], projections.shape[2]}) +
                           " or a stack of them");
        }
        return detector_row(stack, *row);
      };
      const Array flat_row = field_row(flats, "the flat field");
      const Array dark_row = darks.shape.empty() ? Array() : field_row(darks, "the dark field");
      scan.measurement =
          flat_field_normalise(projection_row, flat_row, dark_row, &r, flat_positions);
    } else {
      scan.measurement = flat_field_normalise(projections, flats, darks, &r, flat_positions);
    }
  } catch (const InputError& e) {
    throw InputError(what + ": " + e.what());
  }
  scan.non_finite = compute_stats(scan.measurement).non_finite();
  if (!row) fit_geometry_to_measurement(scan);
  if (!row && scan.measurement.rank() == 3 && !scan.geometry.is_3d()) {
    throw InputError(what + " is a stack " + shape_string(scan.measurement.shape) + " and the " +
                     geometry_type_name(scan.geometry.type) +
                     " geometry is 2D: pick a detector row with --row");
  }
  check_scan(scan, what);
  if (report) *report = r;
  return scan;
}

Scan load_raw_scan(const std::filesystem::path& projections, const std::filesystem::path& flats,
                   const std::filesystem::path& darks, const std::filesystem::path& geometry,
                   FlatFieldReport* report, std::optional<std::size_t> row,
                   const std::filesystem::path& flats_after) {
  Geometry g = Geometry::load(find_geometry(projections, geometry));
  const ArrayFile raw = read_array(projections);
  const Array after = flats_after.empty() ? Array() : read_array(flats_after).array;
  const FlatStack flat = flats_before_after(read_array(flats).array, after, raw.array.shape);
  const Array dark = darks.empty() ? Array() : read_array(darks).array;
  return raw_scan(std::move(g), raw.array, flat.frames, dark, row, projections.string(), report,
                  flat.positions);
}

}  // namespace riner
