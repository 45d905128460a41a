// A float32 dataset [slices, rows, columns] in a new HDF5 file, written a block of slices at a
// time by hyperslab, chunked by slice so that a reader can take any slice alone.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "riner/array.hpp"

namespace riner::io {

// Whether `path` is an HDF5 file (by its signature).
bool is_hdf5_file(const std::filesystem::path& path);

class Hdf5VolumeFile {
 public:
  // Creates `file` (its groups too) holding `dataset` with a "voxel_size_mm" attribute; with
  // `add_to_file`, `file` is an HDF5 file already (InputError if not) and the dataset is added
  // to what it holds, a dataset of that name replaced.
  Hdf5VolumeFile(const std::filesystem::path& file, const std::string& dataset,
                 const std::vector<std::size_t>& shape, double voxel_mm, bool add_to_file = false);
  Hdf5VolumeFile(const Hdf5VolumeFile&) = delete;
  Hdf5VolumeFile& operator=(const Hdf5VolumeFile&) = delete;
  ~Hdf5VolumeFile();
  // Slices [first_slice, first_slice + slices.shape[0]).
  void write(std::size_t first_slice, const Array& slices);
  // Closes the file; Error when HDF5 cannot complete it.
  void close();

 private:
  struct Handles;
  std::unique_ptr<Handles> handles_;
  std::string where_;
};

}  // namespace riner::io
