// Where a scan comes from, as a user names it: a measurement, raw projections with flat and
// dark fields, a tomography HDF5 file, or a scan JSON naming its files; optionally one detector
// row and a centre-of-rotation offset (a number, or estimated). Shared by the CLI's SCAN
// options and the Python module's load_scan().
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "riner/centre.hpp"
#include "riner/flat_field.hpp"
#include "riner/scan.hpp"

namespace riner::app {

struct ScanSource {
  std::string path;      // SCAN
  std::string geometry;  // empty: found beside SCAN (find_geometry)
  std::string flat;      // with a flat, SCAN holds raw intensities
  std::string dark;
  std::optional<std::size_t> row;
  std::string offset_px;  // "", a number, or "auto"
};

struct LoadedScan {
  Scan scan;
  std::optional<FlatFieldReport> flat_field;  // set when SCAN held raw projections
  std::optional<CentreEstimate> centre;       // set by offset_px "auto"
  std::vector<std::string> notes;             // what was done, one line each
};

// InputError (or std::invalid_argument for a usage mistake, e.g. a dark without a flat) with
// a one-line message naming the culprit.
LoadedScan load_scan_source(ScanSource source);

// One line: how many frames went into each field, what became invalid.
std::string flat_field_line(const FlatFieldReport& report);
std::string centre_line(const CentreEstimate& estimate);

}  // namespace riner::app
