// From a detector's raw readings to the measurement riner reconstructs:
// rho = -ln((I - D) / (F - D)), with D the dark field (no beam) and F the flat field (beam, no
// sample), each the per-pixel mean of its frames.
#pragma once

#include <cstddef>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "riner/array.hpp"
#include "riner/scan.hpp"

namespace riner {

struct FlatFieldReport {
  std::size_t flat_frames = 0;
  std::size_t dark_frames = 0;  // 0: no dark given, D = 0
  // Readings with no logarithm (invalid readings, which FBP interpolates): +inf where I - D <= 0
  // under a beam (no light left: metal, or a dead pixel; training keeps the first as a bound,
  // the library's model/starved_readings.hpp), NaN for a non-finite I (beta switches those off).
  std::size_t invalid_readings = 0;
  // The dark field's noise (the median over detector rows of its standard deviation from frame to
  // frame; 0 with fewer than two dark frames), and the invalid readings whose light was above
  // the dark but within kDarkNoiseSigmas of that noise (taken as no light).
  double dark_noise = 0.0;
  std::size_t readings_in_dark_noise = 0;
  // Detector pixels with F - D <= 0 or no finite flat or dark frame: all their readings are NaN.
  std::size_t pixels_without_beam = 0;
  std::size_t pixels = 0;  // of one view
  // Of the invalid readings, those at their integer type's largest count (65535 in uint16, 255
  // in uint8): a saturated detector's, whose -ln under-reads the attenuation.
  std::size_t saturated_readings = 0;
  // Flat series taken at different times (before and after the scan, say) and the beam's
  // change from the first to the last, the median over pixels of (F - D) last / first - 1.
  std::size_t flat_series = 1;
  double flat_change = 0.0;
  // The check of the flats against the projections (flat_field_drift): the air's reading, -ln
  // of its light over the flat's, in the first and the last tenth of the views, and the change
  // between them in units of its noise; NaN when the projections show no air.
  double air_first = std::numeric_limits<double>::quiet_NaN();
  double air_last = std::numeric_limits<double>::quiet_NaN();
  double air_drift_sigmas = 0.0;
};

// Whether the air reads differently at the scan's start and end by more than
// kAirDriftSigmas of its noise and kAirDriftLeast: a beam or detector that drifted during the
// scan, which a flat field taken at one time turns into rings and bands.
constexpr double kAirDriftSigmas = 6.0;
constexpr double kAirDriftLeast = 0.005;
// ... and only where those elements read air at the start or the end (within this of 0, as
// training takes air, model/air_readings.cpp): a sample wider than the field leaves none, and
// its least-attenuated elements read the sample turning (the shared savu stack: 0.34 then
// 0.61, called 24% less light).
constexpr double kAirDriftLevelMost = 0.1;
bool air_drifts(const FlatFieldReport& report);
// One line naming the drift and what to do about it (empty when air_drifts is false).
std::string air_drift_line(const FlatFieldReport& report);

// Where the air (flat_field_drift's least-attenuated elements) reads after the flat field: below
// -kAirBelowZero the projections saw more light than the flat (a flat of another exposure,
// gain or scale: -7 for a flat of ones under counts of thousands); above kAirAbove even the
// least-attenuated elements pass under 5% of the beam (readings that were -ln(I/I0) already,
// or a flat of another detector region). One line saying so, or empty.
constexpr double kAirBelowZero = 0.1;
constexpr double kAirAbove = 3.0;
std::string air_level_line(const FlatFieldReport& report);
// One line on the saturated readings, or empty.
std::string saturation_line(const FlatFieldReport& report);
// Readings of `dtype` (the file's) at its largest count set to NaN, and counted: uint16 and
// uint8 only (a 12-bit camera's 4095 in uint16 is not known from the file).
std::size_t mark_saturated(Array& projections, const std::string& dtype);

// Light less than this many times the dark's noise above the dark is no light (+inf): the
// chance that a pixel that saw none reads more is about 1 in 700.
constexpr double kDarkNoiseSigmas = 3.0;
// ... where the pixel's beam (F - D) is at least e^this times that light: a detector that reads
// through 98% attenuation, where light within the noise is a beam an object (metal) stopped.
// Under a dimmer beam (flats of 100-300 counts over a dark noise of 5-10) half the body's
// readings lie within the noise, and as bounds they left FBP's centre at half its level.
constexpr double kDarkNoiseLeastDepth = 4.0;

// A real detector has a few dead pixels; past this share of pixels without beam the flat field
// is more likely of another detector region, binning or exposure than the projections'.
constexpr double kMostPixelsWithoutBeam = 0.05;
// A note naming the pixels without beam past kMostPixelsWithoutBeam (empty below it).
std::string pixels_without_beam_line(const FlatFieldReport& report);

// projections: [views, elements] or [views, rows, columns]. flats and darks: one frame (the
// shape of one view) or a stack of frames along a first axis, averaged per pixel over their
// finite values; darks may be Array() (no dark: D = 0). InputError when a frame's shape is not a
// view's, or when no reading is left valid.
// flat_positions: where each flat frame was taken on the views' axis (-0.5: before view 0,
// views - 0.5: after the last); frames at one position are a series, averaged. With two or more
// series each view's flat is interpolated linearly between the series either side of it (the
// first's and the last's beyond them): a beam that drifts during the scan. Empty: one series.
Array flat_field_normalise(const Array& projections, const Array& flats, const Array& darks,
                           FlatFieldReport* report = nullptr,
                           const std::vector<double>& flat_positions = {});

// The check of a normalised measurement [views, ...] against drift: the elements (pixels) whose
// median reading over the views is among the lowest 5% (at least 3) are taken for air, and
// their mean reading per view compared between the first and the last tenth of the views.
// Sets report's air_first, air_last and air_drift_sigmas.
void flat_field_drift(const Array& rho, FlatFieldReport& report);

// A scan from raw arrays: normalised, with only detector row `row` (when set: a 2D slice of a
// 3D stack) and checked against the geometry. `what` names the data in messages.
Scan raw_scan(Geometry geometry, const Array& projections, const Array& flats, const Array& darks,
              std::optional<std::size_t> row, const std::string& what,
              FlatFieldReport* report = nullptr, const std::vector<double>& flat_positions = {});

// Flats before the scan and flats after it as one stack with their positions (for
// flat_field_normalise), for projections of `projections_shape`; `after` may be Array() (then
// `before` alone, one series). InputError when their frames differ in shape.
struct FlatStack {
  Array frames;
  std::vector<double> positions;
};
FlatStack flats_before_after(const Array& before, const Array& after,
                             const std::vector<std::size_t>& projections_shape);

// The same from files: each a file, a folder of TIFFs or a pattern (riner/io.hpp's read_array);
// `darks` and `flats_after` may be empty. The geometry as load_scan finds it.
Scan load_raw_scan(const std::filesystem::path& projections, const std::filesystem::path& flats,
                   const std::filesystem::path& darks, const std::filesystem::path& geometry = {},
                   FlatFieldReport* report = nullptr, std::optional<std::size_t> row = {},
                   const std::filesystem::path& flats_after = {});

}  // namespace riner
