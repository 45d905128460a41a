// Tomography HDF5 files as synchrotrons write them, read directly (libhdf5):
//   Data Exchange (APS, tomopy): /exchange/data, /exchange/data_white, /exchange/data_dark,
//                                /exchange/theta (degrees)
//   NeXus NXtomo (ESRF, Diamond): /entry/data/data (or /entry/instrument/detector/data) with
//                                 image_key 0/1/2 (projection/flat/dark) per frame and
//                                 /entry/sample/rotation_angle (degrees)
// and one dataset by its path ("file.h5:/group/dataset") wherever riner reads an array.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "riner/array.hpp"

namespace riner {

struct TomoFile {
  std::string layout;              // "data exchange" or "nxtomo"
  Array projections;               // [views, rows, columns]
  Array flats;                     // [frames, rows, columns]; empty shape when the file has none
  Array darks;                     // likewise
  // Where each flat was taken among the projections (NXtomo's image_key order: the projections
  // before it, less a half); empty when the file does not say (Data Exchange): one series.
  std::vector<double> flat_positions;
  std::vector<double> angles_deg;  // per projection, as the file states them (may be empty)
  std::string dtype;               // the frames' type in the file ("uint16"; read as float32)
  // NXtomo frames neither projection, flat nor dark (image_key 3: invalid; an alignment frame,
  // image_key_control -1): not read.
  std::size_t frames_left_out = 0;
};

// Whether the path names an HDF5 file by its extension (.h5, .hdf5, .hdf, .nxs, .nx).
bool is_hdf5_path(const std::filesystem::path& path);

// InputError naming the file and the dataset for a file that is neither layout, a missing
// dataset, a rank other than 3, or counts that do not match (image_key against the frames,
// angles against the projections).
// With `rows`, only those detector rows of the projections, flats and darks (a hyperslab: a
// slab of a large scan reads its own bytes).
TomoFile read_tomo_file(const std::filesystem::path& path,
                        std::optional<RowRange> rows = std::nullopt);
// The projections' angles as the file states them (degrees; empty where it states none),
// without reading the frames.
std::vector<double> tomo_file_angles(const std::filesystem::path& path);
// The projections' shape [views, rows, columns], from the file's metadata.
std::vector<std::size_t> tomo_file_shape(const std::filesystem::path& path);

// One dataset as float32; with `rows`, only those of a [frames, rows, columns] dataset.
Array read_hdf5_dataset(const std::filesystem::path& file, const std::string& dataset,
                        std::optional<RowRange> rows = std::nullopt);
std::vector<std::size_t> hdf5_dataset_shape(const std::filesystem::path& file,
                                            const std::string& dataset);

// "/volume" where the file holds riner's own volume (riner fbp or reconstruct --out FILE.h5)
// and no tomography layout, else "": a file read by its name alone.
std::string hdf5_volume_dataset(const std::filesystem::path& file);
// A dataset's type in the file, as numpy names it ("uint16", "float64").
std::string hdf5_dataset_dtype(const std::filesystem::path& file, const std::string& dataset);

// "file.h5:/group/dataset" -> {"file.h5", "/group/dataset"}; nullopt for any other path.
std::optional<std::pair<std::filesystem::path, std::string>> split_hdf5_dataset(
    const std::filesystem::path& path);

}  // namespace riner
