// From a detector's raw readings to the measurement riner reconstructs:
// rho = -ln((I - D) / (F - D)), with D the dark field (no beam) and F the flat field (beam, no
// sample), each the per-pixel mean of its frames.
#pragma once

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>

#include "riner/array.hpp"
#include "riner/scan.hpp"

namespace riner {

struct FlatFieldReport {
  std::size_t flat_frames = 0;
  std::size_t dark_frames = 0;  // 0: no dark given, D = 0
  // Readings that became NaN (invalid readings, which beta switches off and FBP interpolates):
  // I - D <= 0 (no light left to take a logarithm of) or a non-finite I.
  std::size_t invalid_readings = 0;
  // Detector pixels with F - D <= 0 or no finite flat or dark frame: all their readings are NaN.
  std::size_t pixels_without_beam = 0;
};

// projections: [views, elements] or [views, rows, columns]. flats and darks: one frame (the
// shape of one view) or a stack of frames along a first axis, averaged per pixel over their
// finite values; darks may be Array() (no dark: D = 0). InputError when a frame's shape is not a
// view's, or when no reading is left valid.
Array flat_field_normalise(const Array& projections, const Array& flats, const Array& darks,
                           FlatFieldReport* report = nullptr);

// A scan from raw arrays: normalised, with only detector row `row` (when set: a 2D slice of a
// 3D stack) and checked against the geometry. `what` names the data in messages.
Scan raw_scan(Geometry geometry, const Array& projections, const Array& flats, const Array& darks,
              std::optional<std::size_t> row, const std::string& what,
              FlatFieldReport* report = nullptr);

// The same from files: each a file, a folder of TIFFs or a pattern (riner/io.hpp's read_array);
// `darks` may be empty. The geometry as load_scan finds it.
Scan load_raw_scan(const std::filesystem::path& projections, const std::filesystem::path& flats,
                   const std::filesystem::path& darks, const std::filesystem::path& geometry = {},
                   FlatFieldReport* report = nullptr, std::optional<std::size_t> row = {});

}  // namespace riner
