#include "riner/flat_field.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "riner/error.hpp"
#include "riner/io.hpp"

namespace riner {

namespace {

// Per-pixel mean over the finite values of a frame or a stack of frames shaped like one view;
// NaN where no frame is finite.
std::vector<double> frame_mean(const Array& frames, const std::vector<std::size_t>& view_shape,
                               const char* what, std::size_t* frame_count) {
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
  std::vector<double> sum(pixels, 0.0);
  std::vector<std::size_t> finite(pixels, 0);
  for (std::size_t f = 0; f < count; ++f) {
    const float* frame = frames.ptr() + f * pixels;
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

}  // namespace

Array flat_field_normalise(const Array& projections, const Array& flats, const Array& darks,
                           FlatFieldReport* report) {
  if (projections.rank() != 2 && projections.rank() != 3) {
    throw InputError("projections are " + shape_string(projections.shape) +
                     "; expected [views, elements] or [views, rows, columns]");
  }
  const std::vector<std::size_t> view_shape(projections.shape.begin() + 1, projections.shape.end());
  const std::size_t pixels = shape_size(view_shape);
  FlatFieldReport r;
  const std::vector<double> flat = frame_mean(flats, view_shape, "the flat field", &r.flat_frames);
  std::vector<double> dark(pixels, 0.0);
  if (!darks.shape.empty()) dark = frame_mean(darks, view_shape, "the dark field", &r.dark_frames);

  // Per pixel: the beam's strength F - D, NaN where there is none.
  std::vector<double> beam(pixels);
  for (std::size_t p = 0; p < pixels; ++p) {
    beam[p] = flat[p] - dark[p];
    if (!(beam[p] > 0.0)) {
      beam[p] = std::numeric_limits<double>::quiet_NaN();
      ++r.pixels_without_beam;
    }
  }
  Array rho(projections.shape);
  const std::size_t views = projections.shape[0];
  for (std::size_t v = 0; v < views; ++v) {
    for (std::size_t p = 0; p < pixels; ++p) {
      const std::size_t i = v * pixels + p;
      const double light = static_cast<double>(projections.data[i]) - dark[p];
      if (!(light > 0.0) || std::isnan(beam[p])) {
        rho.data[i] = std::numeric_limits<float>::quiet_NaN();
        ++r.invalid_readings;
        continue;
      }
      rho.data[i] = static_cast<float>(-std::log(light / beam[p]));
    }
  }
  if (r.invalid_readings == rho.size()) {
    throw InputError(
        "no projection reading is above its dark field under a flat field above "
        "its dark: check the flat and dark files");
  }
  if (report) *report = r;
  return rho;
}

Scan raw_scan(Geometry geometry, const Array& projections, const Array& flats, const Array& darks,
              std::optional<std::size_t> row, const std::string& what, FlatFieldReport* report) {
  Scan scan;
  scan.geometry = std::move(geometry);
  FlatFieldReport r;
  try {
    if (row) {
      // The projections first: their rows are what the user asked for.
      const Array projection_row = detector_row(projections, *row);
      const Array flat_row = detector_row(flats, *row);
      const Array dark_row = darks.shape.empty() ? Array() : detector_row(darks, *row);
      scan.measurement = flat_field_normalise(projection_row, flat_row, dark_row, &r);
    } else {
      scan.measurement = flat_field_normalise(projections, flats, darks, &r);
    }
  } catch (const InputError& e) {
    throw InputError(what + ": " + e.what());
  }
  scan.non_finite = compute_stats(scan.measurement).non_finite();
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
                   FlatFieldReport* report, std::optional<std::size_t> row) {
  Geometry g = Geometry::load(find_geometry(projections, geometry));
  const ArrayFile raw = read_array(projections);
  const Array flat = read_array(flats).array;
  const Array dark = darks.empty() ? Array() : read_array(darks).array;
  return raw_scan(std::move(g), raw.array, flat, dark, row, projections.string(), report);
}

}  // namespace riner
