// Reading and writing arrays in the formats CT people use, chosen by file extension:
//   .npy           NumPy, float32/float64/uint8/uint16/int16/int32/uint32, C or Fortran order,
//                  either byte order
//   .nii           NIfTI-1 single file, read float32/float64/int16/uint16/uint8/int32 with
//                  scl_slope/scl_inter; written as float32
//   .tif/.tiff     TIFF, one page = 2D, several pages = 3D [pages, rows, cols];
//                  float32/uint16/uint8 (read), float32 (written)
//   .raw/.bin      raw samples described by a JSON sidecar "<file>.json":
//                  {"dtype": "float32", "shape": [..], "byte_order": "little", "offset_bytes": 0}
// .h5/.hdf5/.nxs (read only): "file.h5:/group/dataset" names one dataset; a file alone reads as
// the projections of a Data Exchange or NXtomo file (riner/tomo_file.hpp).
// A folder of .tif/.tiff files, or a file-name pattern with * ? [ ] ("tiffs/raw_*.tif", quoted
// on the command line), reads as one stack [files, rows, cols] of 2D images in natural order
// (raw_2 before raw_10). Every reader checks the header against the file size and throws InputError
// naming the file and what is wrong. Every writer writes a temporary file and renames it into
// place, and refuses to write over a file this process has read.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "riner/array.hpp"

namespace riner {

enum class FileFormat { kNpy, kNifti, kTiff, kRaw, kPng, kJson, kHdf5 };

// Format implied by the extension; throws InputError for one riner does not know.
FileFormat format_from_path(const std::filesystem::path& path);
const char* format_name(FileFormat format);

// Removes the temporary files of every write in progress (async-signal-safe: for a handler of
// SIGTERM or SIGINT that then ends the process, so a stopped run leaves no half-written file
// beside its outputs).
void remove_unfinished_outputs() noexcept;
// What the temporary file of a write by process `pid` on this host holds in its name
// (".tmp.HOSTKEY-PID."), and the removal of those in `folder` whose writer on this host has
// ended (a SIGKILL mid-write leaves one): their number. Another host's, and a running
// process's, stay.
std::string temporary_marker(long pid);
std::size_t remove_stale_temporaries(const std::filesystem::path& folder);

struct ArrayFile {
  Array array;
  FileFormat format = FileFormat::kNpy;
  std::string dtype;               // as stored in the file: "float32", "uint16", ...
  std::vector<double> voxel_size;  // per axis in array order, when the file states it (NIfTI)
  std::size_t non_finite = 0;      // NaN and +-inf values in the data
};

ArrayFile read_array(const std::filesystem::path& path);

// Only detector rows `rows` of a stack [views, rows, columns]: read alone where the format lets
// a reader seek (.npy and .raw in C order, .nii, HDF5 by hyperslab, TIFF pages and stacks
// scanline by scanline); Fortran-order files are read whole and cut. InputError for a 2D
// array or rows past its end.
ArrayFile read_array_rows(const std::filesystem::path& path, RowRange rows);

// The array's shape from its header (every format has one), checked against the file's size.
std::vector<std::size_t> read_array_shape(const std::filesystem::path& path);

struct WriteOptions {
  std::vector<double> voxel_size;  // per axis in array order; NIfTI pixdim (mm)
};

void write_array(const std::filesystem::path& path, const Array& array,
                 const WriteOptions& options = {});

// Display window for previews.
struct Window {
  float lo = 0.0f;
  float hi = 1.0f;
};

// Window from the given percentiles of the finite values (1 and 99 by default).
Window percentile_window(const Array& image, double lo_percent = 1.0, double hi_percent = 99.0);

// What a preview shows: a 2D image as it is; of a 3D volume [z, y, x], its three central slices
// side by side, 4 pixels apart: axial (slice z/2), coronal (row y/2) and sagittal (column x/2),
// the last two with +z up. InputError for other ranks.
Array preview_image(const Array& image);
// The same panel from the three planes alone (a volume streamed slab by slab): axial [y, x],
// coronal [z, x] and sagittal [z, y], z ascending. InputError when they do not fit together.
Array preview_panel(const Array& axial, const Array& coronal, const Array& sagittal);
// Row y of every slice of a volume [z, y, x]: [z, x]; column x: [z, y].
Array coronal_plane(const Array& volume, std::size_t y);
Array sagittal_plane(const Array& volume, std::size_t x);

// 8-bit grey PNG of a 2D array mapped through the window; of a 3D one, its three central slices
// side by side (axial, coronal, sagittal; +z up), the percentile window taken over all three.
void write_png(const std::filesystem::path& path, const Array& image, const Window& window);
void write_png(const std::filesystem::path& path, const Array& image);  // percentile window

// 8-bit RGB PNG; rgb is [rows, cols, 3] in 0..255.
void write_png_rgb(const std::filesystem::path& path, const std::vector<unsigned char>& rgb,
                   std::size_t rows, std::size_t cols);

// Text outputs (JSON summaries, CSV histories), written atomically like every other output.
void write_text(const std::filesystem::path& path, std::string_view text);
std::string read_text(const std::filesystem::path& path);

// Marks a path as an input of this process: writers refuse to replace it. Readers call this
// themselves; call it for inputs read by other means.
void register_input(const std::filesystem::path& path);
// Inputs this thread registers while it lives are released when it ends: a library caller's
// read (a Python session's read_array) guards the files only during that call, not every
// later write of the process. Other threads' registrations, and one the same file had before,
// stay.
class InputScope {
 public:
  InputScope();
  ~InputScope();
  InputScope(const InputScope&) = delete;
  InputScope& operator=(const InputScope&) = delete;

 private:
  std::vector<std::filesystem::path> registered_;
  std::vector<std::filesystem::path>* outer_;  // an enclosing scope's, restored at the end
};

// InputError "refusing to overwrite an input file" when `path` is a registered input (the same
// file or folder by any name; a folder of TIFFs read as a stack is one): what writers check
// before they replace it.
void refuse_overwriting_input(const std::filesystem::path& path);

}  // namespace riner
