// Where a scan comes from, as a user names it: a measurement, raw projections with flat and
// dark fields, a tomography HDF5 file, or a scan JSON naming its files; optionally one detector
// row and a centre-of-rotation offset (a number, or estimated). The one home of reading scans:
// the CLI's SCAN options, the Python module's load_scan() and the slab scheduler all come here,
// whole (load_scan_source) or a slab of detector rows at a time (ScanRows).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "riner/centre.hpp"
#include "riner/flat_field.hpp"
#include "riner/scan.hpp"

namespace riner {

struct ScanSource {
  std::string path;      // SCAN
  std::string geometry;  // empty: found beside SCAN (find_geometry)
  std::string flat;      // with a flat, SCAN holds raw intensities
  std::string dark;
  std::optional<std::size_t> row;
  std::string offset_px;  // "", a number, or "auto"
  std::string flat_after;  // flats taken after the scan: each view's flat interpolated
};

struct LoadedScan {
  Scan scan;
  std::optional<FlatFieldReport> flat_field;  // set when SCAN held raw projections
  std::optional<CentreEstimate> centre;       // set by offset_px "auto"
  std::vector<std::string> notes;             // what was done, one line each
  // What the readings say against the geometry (riner/geometry_doubts.hpp).
  std::vector<std::string> geometry_doubts;
};

// InputError (or std::invalid_argument for a usage mistake, e.g. a dark without a flat) with
// a one-line message naming the culprit.
LoadedScan load_scan_source(ScanSource source);

// The geometry file a source is read under: the one given, a scan JSON itself, or the one found
// beside the scan; InputError when there is none (or the scan JSON names no files).
std::filesystem::path geometry_file_of(ScanSource source);

// A scan opened to be read a slab of detector rows at a time: the geometry and the shape come
// from the files' headers, the data only when rows are asked for, so a scan larger than memory
// streams (riner/slab_run.hpp). Raw projections are normalised by the flats and darks of the
// same rows. The centre offset is applied like load_scan_source's; "auto" is estimated once,
// from up to kCentreRows rows around the middle of the detector (a cone's: about its source's
// plane).
class ScanRows {
 public:
  static constexpr std::size_t kCentreRows = 8;
  static constexpr std::size_t kRangeRows = 2;
  // InputError as load_scan_source; also for a 2D scan or a `row` (a slice is read whole). A
  // stack of rows under a parallel2d geometry is read as stack_of_slices of it.
  explicit ScanRows(ScanSource source);
  const Geometry& geometry() const { return geometry_; }  // the whole detector's
  std::size_t rows() const { return geometry_.n_v; }
  const std::vector<std::size_t>& shape() const { return shape_; }  // [views, rows, columns]
  const std::optional<CentreEstimate>& centre() const { return centre_; }
  const std::string& what() const { return source_.path; }
  const ScanSource& files() const { return source_; }  // the names, a scan JSON resolved
  bool raw() const { return !source_.flat.empty() || tomo_file_; }
  // Rows `rows` as a scan: measurement [views, count, columns], geometry with the detector cut to
  // those rows (detector_rows_geometry). InputError naming the data for bad readings.
  Scan read(RowRange rows, FlatFieldReport* report = nullptr) const;
  // What reading the files found worth saying before any slab (a tomography file's own angles
  // against the geometry's).
  const std::vector<std::string>& notes() const { return notes_; }
  // riner/geometry_doubts.hpp on kRangeRows rows about the middle of the detector (read now;
  // a cone's: about its source's plane); empty where those rows read nothing.
  std::vector<std::string> geometry_doubts() const;

 private:
  ScanSource source_;
  bool tomo_file_ = false;
  Geometry geometry_;
  std::vector<std::size_t> shape_;
  std::optional<CentreEstimate> centre_;
  std::vector<std::string> notes_;
};

// A note where a tomography file's own angles (degrees, or radians) span other than the
// geometry's by more than 2 degrees and a view's step (a 360-degree scan under a 180-degree
// geometry reconstructs garbage); empty when they agree or the file states none.
std::string file_angles_note(const std::string& path, const std::vector<double>& angles_deg,
                             const Geometry& g);

// One line: how many frames went into each field, what became invalid.
std::string flat_field_line(const FlatFieldReport& report);
// What a raw scan's normalisation tells: flat_field_line, then the pixels without beam and the
// beam's drift where they say anything.
std::vector<std::string> flat_field_notes(const FlatFieldReport& report);
std::string centre_line(const CentreEstimate& estimate);

}  // namespace riner
