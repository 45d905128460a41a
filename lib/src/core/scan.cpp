#include "riner/scan.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <nlohmann/json.hpp>

#include "io/file_access.hpp"
#include "io/stack.hpp"
#include "util/robust_statistics.hpp"

#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/tomo_file.hpp"
#include "util/user_json.hpp"

namespace riner {

namespace {

// Line integrals -ln(I / I0) of a real scan stay within a few tens (a 16-bit detector's range
// is ln 65536 = 11, a simulation's 10^7 photons 16): where even the least of them exceeds this,
// the file holds intensities, which riner would reconstruct into garbage without a word.
constexpr double kLargestLeastReading = 20.0;
// "The least": the 1st percentile of the positive ones, since raw counts read 0 on dead elements
// (a few dead columns would otherwise hide a whole file of intensities).
constexpr double kLeastShare = 0.01;
// Beyond this share of unusable readings (NaN, infinite or beyond kLargestReading) what is
// left cannot carry an image: FBP would interpolate it from the few.
constexpr double kMostUnusableShare = 0.9;
constexpr std::size_t kReadingsLooked = std::size_t{1} << 20;
// Transmissions: at least 0 but for noise, at most 1 but for the detector's gains (the paper's
// responses reach 1.25), the outer columns' median near 1 (air), the least readings below a
// share of it (an object).
constexpr double kTransmissionNoise = 0.05;
constexpr double kLargestTransmission = 1.5;
constexpr double kAirTransmissionLow = 0.8;
constexpr double kAirTransmissionHigh = 1.25;
constexpr double kTransmissionObjectShare = 0.6;

struct ReadingsLook {
  double unusable_share = 0.0;
  double least = 0.0;  // the 1st percentile of the usable positive ones (NaN: none)
};

// Calls look(i) for at most kReadingsLooked indices of `measurement`, one at a scrambled place
// in each of as many equal stretches (a stack in milliseconds; an even stride could land on one
// dead column throughout). Returns how many.
template <class Look>
std::size_t look_at_some(const Array& measurement, Look look) {
  const std::size_t stride = std::max<std::size_t>(1, measurement.size() / kReadingsLooked);
  const std::size_t looked = measurement.size() / stride;
  for (std::size_t k = 0; k < looked; ++k) look(k * stride + (k * 2654435761u) % stride);
  return looked;
}

ReadingsLook look_at_readings(const Array& measurement) {
  std::size_t usable = 0;
  std::vector<double> positive;
  const std::size_t looked = look_at_some(measurement, [&](std::size_t i) {
    const float v = measurement.data[i];
    if (!(std::fabs(v) <= kLargestReading)) return;  // NaN fails it too
    ++usable;
    if (v > 0.0f) positive.push_back(v);
  });
  ReadingsLook out;
  if (looked == 0) return out;
  out.unusable_share = 1.0 - static_cast<double>(usable) / static_cast<double>(looked);
  out.least = positive.empty() ? std::nan("") : util::quantile(positive, kLeastShare);
  return out;
}

}  // namespace

double median_view_largest(const Array& measurement, std::size_t views) {
  if (views == 0 || measurement.size() == 0) return 0.0;
  const std::size_t per_view = measurement.size() / views;
  std::vector<float> view_largest;
  view_largest.reserve(views);
  for (std::size_t v = 0; v < views; ++v) {
    float largest = -1.0f;
    const float* line = measurement.ptr() + v * per_view;
    for (std::size_t k = 0; k < per_view; ++k) {
      const float m = std::fabs(line[k]);
      if (m <= kLargestReading && m > largest) largest = m;
    }
    if (largest >= 0.0f) view_largest.push_back(largest);
  }
  if (view_largest.empty()) return 0.0;
  const auto middle = view_largest.begin() + static_cast<std::ptrdiff_t>(view_largest.size() / 2);
  std::nth_element(view_largest.begin(), middle, view_largest.end());
  return *middle;
}

double edge_reading_share(const Array& measurement) {
  if (measurement.rank() < 2 || measurement.shape.back() < 8) return 0.0;
  const std::size_t n = measurement.shape.back();
  const std::size_t lines = measurement.size() / n;
  std::vector<double> shares;
  const auto end_reading = [n](const float* line, bool from_left) {
    std::vector<double> outer;
    for (std::size_t k = 0; k < n && outer.size() < 3; ++k) {
      const float x = line[from_left ? k : n - 1 - k];
      if (std::fabs(x) <= kLargestReading) outer.push_back(x);
    }
    if (outer.empty()) return std::nan("");
    std::sort(outer.begin(), outer.end());
    return outer[outer.size() / 2];
  };
  for (std::size_t l = 0; l < lines; ++l) {
    const float* line = measurement.ptr() + l * n;
    float largest = 0.0f;
    for (std::size_t k = 0; k < n; ++k) {
      if (std::fabs(line[k]) <= kLargestReading) largest = std::max(largest, line[k]);
    }
    const double edge = std::fmax(end_reading(line, true), end_reading(line, false));
    if (largest > 0.0f && std::isfinite(edge)) shares.push_back(edge / largest);
  }
  return shares.empty() ? 0.0 : util::quantile(shares, 0.5);
}

float largest_reading(const Array& measurement, std::size_t views) {
  const double limit =
      std::max(kLeastSpikeLimit, kSpikeFactor * median_view_largest(measurement, views));
  return static_cast<float>(std::min(limit, static_cast<double>(kLargestReading)));
}

std::size_t count_corrupt_readings(const Array& measurement, std::size_t views) {
  const float largest = largest_reading(measurement, views);
  return static_cast<std::size_t>(
      std::count_if(measurement.data.begin(), measurement.data.end(),
                    [&](float x) { return std::isfinite(x) && !(std::fabs(x) <= largest); }));
}

std::size_t mark_corrupt_readings(Array& measurement, std::size_t views) {
  const float largest = largest_reading(measurement, views);
  std::size_t marked = 0;
  for (float& x : measurement.data) {
    if (std::isfinite(x) && !(std::fabs(x) <= largest)) x = NAN, ++marked;
  }
  return marked;
}

std::optional<std::string> uniform_readings(const Scan& scan) {
  float low = 0.0f, high = 0.0f;
  bool any = false;
  for (float x : scan.measurement.data) {
    if (!std::isfinite(x)) continue;
    if (!any) low = high = x;
    low = std::min(low, x);
    high = std::max(high, x);
    any = true;
    if (high > low) return std::nullopt;
  }
  if (!any) return std::nullopt;  // check_scan says so
  if (low == 0.0f) {
    return std::string(
        "every reading is 0: the rays crossed nothing (an empty or wrong dataset?); there is no "
        "object to reconstruct");
  }
  char line[240];
  std::snprintf(line, sizeof(line),
                "every reading is %.6g: no object reads alike on every ray (a flat or dark frame "
                "given as the scan, or readings that are not -ln(I/I0)?)",
                low);
  return std::string(line);
}

void check_scan(const Scan& scan, std::string_view what) {
  check_array(scan.measurement, what);
  scan.geometry.check_measurement_shape(scan.measurement.shape, what);
  // Counted here, not taken from scan.non_finite: a caller's count may be anything.
  const auto non_finite = static_cast<std::size_t>(
      std::count_if(scan.measurement.data.begin(), scan.measurement.data.end(),
                    [](float x) { return !std::isfinite(x); }));
  if (scan.measurement.size() > 0 && non_finite >= scan.measurement.size()) {
    throw NoReadingsError(std::string(what) + ": all " + std::to_string(scan.measurement.size()) +
                          " values are NaN or infinite; there is nothing to reconstruct");
  }
  const ReadingsLook look = look_at_readings(scan.measurement);
  char line[200];
  if (look.unusable_share > kMostUnusableShare) {
    std::snprintf(line, sizeof(line),
                  "%.1f%% of the readings are NaN, infinite or beyond %.0e: there is too little "
                  "left to reconstruct",
                  100.0 * look.unusable_share, static_cast<double>(kLargestReading));
    throw NoReadingsError(std::string(what) + ": " + line);
  }
  if (look.least > kLargestLeastReading) {
    std::snprintf(line, sizeof(line), "99%% of the readings exceed %.0f (the 1st percentile: %.4g)",
                  kLargestLeastReading, look.least);
    throw InputError(std::string(what) + ": " + line +
                     ", beyond any line integral -ln(I/I0): these look like raw intensities; "
                     "give their flat field (--flat and --dark) or take -ln(I/I0) first");
  }
}

std::optional<std::string> transmission_note(const Scan& scan) {
  const Array& m = scan.measurement;
  const std::size_t n_u = scan.geometry.n_u;
  if (m.size() == 0 || n_u < 8) return std::nullopt;
  std::vector<double> all;
  std::vector<double> edges;
  // The outer 2% of columns at either end (two at least).
  const std::size_t outer = std::max<std::size_t>(2, n_u / 50);
  look_at_some(m, [&](std::size_t i) {
    const float v = m.data[i];
    if (!std::isfinite(v)) return;
    all.push_back(v);
    const std::size_t u = i % n_u;
    if (u < outer || u >= n_u - outer) edges.push_back(v);
  });
  if (all.size() < 100 || edges.size() < 10) return std::nullopt;
  const double least = util::quantile(all, kLeastShare);
  const double most = util::quantile(all, 1.0 - kLeastShare);
  const double edge = util::quantile(edges, 0.5);
  if (least < -kTransmissionNoise || most > kLargestTransmission || edge < kAirTransmissionLow ||
      edge > kAirTransmissionHigh || least > kTransmissionObjectShare * edge) {
    return std::nullopt;
  }
  char line[320];
  std::snprintf(line, sizeof(line),
                "note: the readings look like transmissions I/I0, not -ln(I/I0): all within "
                "%.2f..%.2f, the detector's outer columns at %.2f (air reads 0 as a line "
                "integral); take -ln of them first",
                least, most, edge);
  return std::string(line);
}

std::optional<std::string> negative_readings_note(const Scan& scan) {
  const Array& m = scan.measurement;
  const double below = -std::max(
      kLeastNegative, kNegativeOfLargest * median_view_largest(m, scan.geometry.n_views()));
  std::size_t finite = 0, negative = 0;
  float least = 0.0f;
  for (float v : m.data) {
    if (!(std::fabs(v) <= kLargestReading)) continue;
    ++finite;
    if (v < below) ++negative, least = std::min(least, v);
  }
  if (finite == 0 || negative < 10 ||
      static_cast<double>(negative) <= kNegativeShare * static_cast<double>(finite)) {
    return std::nullopt;
  }
  char line[320];
  std::snprintf(line, sizeof(line),
                "note: %.2g%% of the readings lie below %.2g (down to %.3g), more light than the "
                "flat field gives, far beyond noise: readings of the wrong sign, or a flat or "
                "dark of another exposure?",
                100.0 * static_cast<double>(negative) / static_cast<double>(finite), below,
                static_cast<double>(least));
  return std::string(line);
}

std::filesystem::path find_geometry(const std::filesystem::path& measurement,
                                    const std::filesystem::path& geometry) {
  if (const auto named = split_hdf5_dataset(measurement)) {
    return find_geometry(named->first, geometry);
  }
  if (!io::is_stack_path(measurement)) {
    io::input_file_size(measurement);  // a missing scan is the first thing to report
  }
  if (!geometry.empty()) return geometry;
  std::vector<std::filesystem::path> folders;
  if (io::is_stack_path(measurement)) {
    // Absolute first: "." and a pattern in the working folder have no parent to look beside.
    std::filesystem::path folder = std::filesystem::absolute(measurement).lexically_normal();
    if (folder.filename().empty()) folder = folder.parent_path();               // "tiffs/", "."
    if (!std::filesystem::is_directory(folder)) folder = folder.parent_path();  // a pattern
    folders = {folder, folder.parent_path()};
  } else {
    folders = {measurement.parent_path()};
  }
  for (const std::filesystem::path& folder : folders) {
    const std::filesystem::path candidate = folder / "geometry.json";
    if (std::filesystem::exists(candidate)) return candidate;
  }
  throw InputError(measurement.string() +
                   ": no geometry given and no geometry.json beside it (use --geometry)");
}

void require_slice_geometry(const Geometry& g) {
  if (g.is_3d()) {
    throw InputError(
        "a detector row (--row) is reconstructed as one slice under a 2D geometry; "
        "the geometry is " +
        std::string(geometry_type_name(g.type)) +
        ": give a 2D one, or leave out the row to reconstruct the whole stack");
  }
}

Scan load_scan(const std::filesystem::path& measurement, const std::filesystem::path& geometry,
               std::optional<std::size_t> row) {
  Scan scan;
  scan.geometry = Geometry::load(find_geometry(measurement, geometry));
  if (row) require_slice_geometry(scan.geometry);
  ArrayFile file = read_array(measurement);
  if (row) {
    try {
      scan.measurement = detector_row(file.array, *row);
    } catch (const InputError& e) {
      throw InputError(measurement.string() + ": " + e.what());
    }
    scan.non_finite = compute_stats(scan.measurement).non_finite();
  } else {
    scan.measurement = std::move(file.array);
    scan.non_finite = file.non_finite;
  }
  if (!row) fit_geometry_to_measurement(scan);
  check_scan(scan, measurement.string());
  return scan;
}

void fit_geometry_to_measurement(Scan& scan) {
  std::vector<std::size_t>& shape = scan.measurement.shape;
  scan.geometry = geometry_for_shape(scan.geometry, shape);
  if (!scan.geometry.is_3d() && shape.size() == 3 && shape[1] == 1) shape.erase(shape.begin() + 1);
}

std::optional<ScanFiles> read_scan_files(const std::filesystem::path& scan_json) {
  const std::string where = scan_json.string();
  const nlohmann::json root = util::parse_user_json(read_text(scan_json), where);
  if (!root.is_object() || !root.contains("files")) return std::nullopt;
  const nlohmann::json& files = root["files"];
  if (!files.is_object()) throw InputError(where + ": files must be an object");
  const std::filesystem::path folder = scan_json.parent_path();
  ScanFiles out;
  for (const auto& [key, value] : files.items()) {
    std::filesystem::path* slot = key == "measurement"   ? &out.measurement
                                  : key == "projections" ? &out.projections
                                  : key == "flat"        ? &out.flat
                                  : key == "dark"        ? &out.dark
                                  : key == "flat_after"  ? &out.flat_after
                                                         : nullptr;
    if (!slot) {
      throw InputError(where + ": files." + key +
                       " is not a scan file (measurement, projections, flat, dark, flat_after)");
    }
    if (!value.is_string() || value.get<std::string>().empty()) {
      throw InputError(where + ": files." + key + " must be a path");
    }
    *slot = folder / value.get<std::string>();
  }
  if (out.measurement.empty() == out.projections.empty()) {
    throw InputError(where + ": files needs either measurement (rho) or projections (raw)");
  }
  if (!out.measurement.empty() && !(out.flat.empty() && out.dark.empty())) {
    throw InputError(where +
                     ": files.flat and files.dark go with projections (raw), not measurement");
  }
  if (out.flat.empty() && !out.dark.empty()) {
    throw InputError(where + ": files.dark needs files.flat");
  }
  if (out.flat.empty() && !out.flat_after.empty()) {
    throw InputError(where + ": files.flat_after needs files.flat");
  }
  return out;
}

}  // namespace riner
