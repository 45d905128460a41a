// A volume [slices, rows, columns] of float32 written a block of axial slices at a time, so
// that a volume larger than memory is written as its slabs are reconstructed. Where it goes is
// named as for write_array (riner/io.hpp):
//   vol.npy, vol.nii, vol.raw (+ vol.raw.json)  each block written in place, in any order
//   vol.h5 or vol.h5:/group/dataset              an HDF5 dataset (default /volume), chunked by
//                                                slice, any order
//   vol.tif                                      one page per slice, blocks in order
//   a folder (a path without an extension)       one TIFF per slice, slice_00000.tif ...
// A file appears under its name only when every slice is in: it is written under a temporary
// name and close() renames it; a writer destroyed without close() removes it. In a folder each
// slice file is written atomically as it comes. Like every riner writer, it refuses to write
// over an input of this process.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "riner/array.hpp"

namespace riner {

class VolumeWriter {
 public:
  // InputError for a target riner cannot write, a shape that is not [slices, rows, columns], or
  // a folder that already holds slices (but an unfinished volume's, kUnfinishedMarker).
  VolumeWriter(const std::string& target, const std::vector<std::size_t>& shape, double voxel_mm);
  VolumeWriter(const VolumeWriter&) = delete;
  VolumeWriter& operator=(const VolumeWriter&) = delete;
  ~VolumeWriter();

  // Slices [first_slice, first_slice + slices.shape[0]) as [count, rows, columns]; each slice
  // once. std::invalid_argument for a block that does not fit the volume.
  void write(std::size_t first_slice, const Array& slices);
  // Every slice written: puts the file in place. Error naming the first missing slice.
  void close();

  // What was asked for ("vol.h5:/volume", "slices/"), for messages.
  const std::string& target() const { return target_; }
  // A folder target's file for slice k.
  static std::filesystem::path slice_file(const std::filesystem::path& folder, std::size_t k);
  // In a folder target while its slices are written, removed by close(): a folder that still
  // holds it after a stop is no volume (reading it as a stack is refused), and the next
  // writer into it replaces its slices.
  static constexpr const char* kUnfinishedMarker = "riner-unfinished.txt";

  class Sink;

 private:
  std::string target_;
  std::vector<std::size_t> shape_;
  std::vector<bool> written_;
  std::unique_ptr<Sink> sink_;
};

}  // namespace riner
