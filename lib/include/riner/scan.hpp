// A scan: the log-normalised measurement ρ̃ plus the geometry it was taken with (the scan
// contract of METHOD.md §3).
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include "riner/array.hpp"
#include "riner/geometry.hpp"

namespace riner {

// Readings beyond this magnitude are no line integral (rho = -ln(I/I0) of a real scan stays
// below a few tens; a scaled integer store, x1000, below 10^5) nor raw counts: a corrupt value,
// which FBP repairs and training leaves out like a non-finite one (at 1e20, two readings of
// 1e19 made an FBP image of +-1e17 without a word).
constexpr float kLargestReading = 1e6f;
// A spike below kLargestReading (five readings of 1e5 among readings of 3 made FBP's image
// -52 dB, unsaid): the largest magnitude a reading of `measurement` ([views, ...]) may have is
// at most kSpikeFactor times the median over views of each view's largest finite magnitude (an
// object is seen in every view; a spike in one), and never under kLeastSpikeLimit (rho = 50,
// e^-50 of the beam, is beyond any detector), so no real object's ray passes for one.
constexpr double kSpikeFactor = 100.0;
constexpr double kLeastSpikeLimit = 50.0;
float largest_reading(const Array& measurement, std::size_t views);
// The median over views of each view's largest finite magnitude (readings beyond kLargestReading
// left out); 0 when no view reads any.
double median_view_largest(const Array& measurement, std::size_t views);
// The finite readings beyond largest_reading: counted, or set to NaN (and counted) for those
// that treat them as unread (training, the centre's search).
std::size_t count_corrupt_readings(const Array& measurement, std::size_t views);
std::size_t mark_corrupt_readings(Array& measurement, std::size_t views);

// How far the object reaches the detector's ends: over detector lines (each view's row), the
// median of the larger of the two ends' readings (each the median of its 3 outermost finite
// columns) over the line's largest. About 0 where air lies beyond the object at both ends (the
// shared scans: 0.001-0.053); an object wider than the field of view reads a good share there.
double edge_reading_share(const Array& measurement);

struct Scan {
  Array measurement;  // [views, elements] in 2D, [views, rows, columns] in 3D
  Geometry geometry;
  std::size_t non_finite = 0;  // NaN/inf measurements (dead elements), kept as they are
};

// The geometry file of a measurement: `geometry` when given, else "geometry.json" beside the
// measurement (for a folder or pattern of images, riner/io.hpp: in its folder, then beside
// that folder). InputError when there is none.
std::filesystem::path find_geometry(const std::filesystem::path& measurement,
                                    const std::filesystem::path& geometry = {});

// Reads both files and checks they belong together; the geometry as find_geometry finds it. A
// stack of rows under a parallel2d geometry (without `row`) is read under stack_of_slices of it:
// one slice per row.
// The measurement is a file, a folder of TIFFs or a pattern (read_array); with `row`, only that
// detector row of a stack (a 2D slice). Throws InputError when the shapes disagree or no
// measurement is finite.
Scan load_scan(const std::filesystem::path& measurement, const std::filesystem::path& geometry = {},
               std::optional<std::size_t> row = {});

// A scan JSON: a geometry file whose "files" member names the scan's data, so one file
// describes a scan. Paths are relative to the JSON's folder; each may be a file, a folder of
// TIFFs, a pattern or FILE.h5:/dataset:
//   "files": {"measurement": "sino.npy"}                       (rho, log-normalised)
//   "files": {"projections": "tiffs", "flat": "flat_*.tif", "dark": "dark.tif"}  (raw)
//   "files": {"projections": "scan.h5"}           (a Data Exchange / NXtomo file's own fields)
struct ScanFiles {
  std::filesystem::path measurement;  // the log-normalised measurement, or
  std::filesystem::path projections;  // raw intensities, with
  std::filesystem::path flat;         // their flat field (may be empty for a tomography file)
  std::filesystem::path dark;         // and dark field (may be empty: D = 0)
  std::filesystem::path flat_after;   // flats taken after the scan (may be empty)
};

// The "files" of a scan JSON; std::nullopt when it has none. InputError naming the JSON for
// a malformed block (not an object, an unknown or non-string member, both or neither of
// measurement and projections, a flat or dark beside a measurement).
std::optional<ScanFiles> read_scan_files(const std::filesystem::path& scan_json);

// Checks a measurement array against its geometry: its shape; InputError when every value is
// NaN or infinite, when nearly all are (or beyond kLargestReading), or when nearly all exceed
// what any line integral reaches (raw intensities: give the flat field).
void check_scan(const Scan& scan, std::string_view what = "measurement");

// A whole measurement read under its geometry (geometry_for_shape): a stack of rows beside a
// parallel2d geometry is a slice per row, and a stack of one row is that row's 2D scan.
void fit_geometry_to_measurement(Scan& scan);
// InputError unless `g` is a 2D geometry, the one a single detector row is a slice of.
void require_slice_geometry(const Geometry& g);

// A note when the readings look like transmissions I/I0 rather than -ln(I/I0): all within
// about 0..1 (a detector's gains let air read up to 1.25), the detector's outer columns near 1
// (where air reads 0 as a line integral) and some readings far below them. Only a note: a pipe's
// wall seen edge-on at the detector's ends reads like that too.
std::optional<std::string> transmission_note(const Scan& scan);

// A note when more than kNegativeShare of the finite readings lie below -max(kLeastNegative,
// kNegativeOfLargest x the median view's largest reading): more light than the flat field
// gives, far beyond noise (a band of elements with the wrong sign trained to 9 dB, unsaid; the
// shared real scans read no lower than -0.17).
constexpr double kLeastNegative = 0.5;
constexpr double kNegativeOfLargest = 0.2;
constexpr double kNegativeShare = 0.001;
std::optional<std::string> negative_readings_note(const Scan& scan);

// When every finite reading of a whole scan is one value, why that is no scan to reconstruct
// (an InputError's text); nullopt otherwise. All 0: the rays crossed nothing (an empty or wrong
// dataset); any other value: no object reads alike on every ray (a flat or dark frame given as
// the scan, or readings that are no line integrals). Before: an all-zero scan wrote a zero image
// and an all-ones scan trained to an 11 dB pattern, both with exit 0 (the audit).
std::optional<std::string> uniform_readings(const Scan& scan);

}  // namespace riner
