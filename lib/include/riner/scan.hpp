// A scan: the log-normalised measurement ρ̃ plus the geometry it was taken with (the scan
// contract of METHOD.md §3).
#pragma once

#include <filesystem>
#include <optional>

#include "riner/array.hpp"
#include "riner/geometry.hpp"

namespace riner {

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

// Reads both files and checks they belong together; the geometry as find_geometry finds it.
// The measurement is a file, a folder of TIFFs or a pattern (read_array); with `row`, only that
// detector row of a stack (a 2D slice). Throws InputError when the shapes disagree or no
// measurement is finite.
Scan load_scan(const std::filesystem::path& measurement, const std::filesystem::path& geometry = {},
               std::optional<std::size_t> row = {});

// Checks a measurement array against its geometry (shape, at least one finite value).
void check_scan(const Scan& scan, std::string_view what = "measurement");

}  // namespace riner
