// One reader and writer per file format; array_io.cpp dispatches by extension. Writers write
// exactly the path they are given (array_io.cpp passes a temporary file and renames it).
#pragma once

#include <filesystem>
#include <memory>
#include <string>
#include <optional>
#include <vector>

#include "riner/io.hpp"

namespace riner::io {

ArrayFile read_npy(const std::filesystem::path& path);
std::vector<std::size_t> npy_shape(const std::filesystem::path& path);
// Rows of a C-order stack by seeking; nullopt for a Fortran-order file (read it whole).
std::optional<ArrayFile> read_npy_rows(const std::filesystem::path& path, RowRange rows);
void write_npy(const std::filesystem::path& path, const Array& array);
// What write_npy puts before the float32 C-order data.
std::string npy_header(const std::vector<std::size_t>& shape);

ArrayFile read_nifti(const std::filesystem::path& path);
// The shape from the header (352 bytes read), checked against the file's size.
std::vector<std::size_t> nifti_shape(const std::filesystem::path& path);
// Rows of a stack by seeking (scaled by scl_slope/scl_inter); nullopt for a file not 3D.
std::optional<ArrayFile> read_nifti_rows(const std::filesystem::path& path, RowRange rows);
void write_nifti(const std::filesystem::path& path, const Array& array,
                 const std::vector<double>& voxel_size);
// What write_nifti puts before the float32 data (InputError for a shape NIfTI-1 cannot hold).
std::string nifti_header(const std::filesystem::path& path, const std::vector<std::size_t>& shape,
                         const std::vector<double>& voxel_size);

ArrayFile read_tiff(const std::filesystem::path& path);
// Rows `rows` of every page: [count, cols] for one page, [pages, count, cols] for several.
ArrayFile read_tiff_rows(const std::filesystem::path& path, RowRange rows);
std::vector<std::size_t> tiff_shape(const std::filesystem::path& path);
// pixel_mm (> 0): the pixels' size, as TIFF's resolution in pixels per centimetre (what Fiji and
// tifffile read); the pages' spacing has no standard tag and is not written.
void write_tiff(const std::filesystem::path& path, const Array& array, double pixel_mm = 0.0);
// A float32 TIFF written a page at a time, in order (libtiff appends directories).
class TiffPageWriter {
 public:
  TiffPageWriter(const std::filesystem::path& path, std::size_t pages, std::size_t rows,
                 std::size_t cols, double pixel_mm = 0.0);
  TiffPageWriter(const TiffPageWriter&) = delete;
  TiffPageWriter& operator=(const TiffPageWriter&) = delete;
  ~TiffPageWriter();
  void append(const float* page);  // rows x cols values
  void close();                    // Error when the file cannot be completed

 private:
  struct File;
  std::unique_ptr<File> file_;
  std::filesystem::path path_;
  std::size_t pages_, rows_, cols_, written_ = 0;
  double pixel_mm_ = 0.0;
};

// The sidecar is "<path>.json".
ArrayFile read_raw(const std::filesystem::path& path);
std::vector<std::size_t> raw_shape(const std::filesystem::path& path);
std::optional<ArrayFile> read_raw_rows(const std::filesystem::path& path, RowRange rows);
// voxel_size (mm per axis, in array order; empty: not stated) as "voxel_size_mm".
std::string raw_sidecar_json(const std::vector<std::size_t>& shape,
                             const std::vector<double>& voxel_size = {});

// 8-bit PNG of prepared pixels (rows x cols x channels).
void write_png_gray8(const std::filesystem::path& path, const std::vector<unsigned char>& pixels,
                     std::size_t rows, std::size_t cols);
void write_png_rgb8(const std::filesystem::path& path, const std::vector<unsigned char>& pixels,
                    std::size_t rows, std::size_t cols);

// C-order copy of data stored in Fortran (first axis fastest) order.
std::vector<float> fortran_to_c_order(const std::vector<float>& data,
                                      const std::vector<std::size_t>& shape);

}  // namespace riner::io
