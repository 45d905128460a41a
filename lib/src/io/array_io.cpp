// Format dispatch, atomic outputs and previews.
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <optional>
#include <utility>

#include "io/file_access.hpp"
#include "io/row_blocks.hpp"
#include "io/formats.hpp"
#include "io/stack.hpp"
#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/volume_writer.hpp"
#include "riner/tomo_file.hpp"
#include "util/atomic_file.hpp"

namespace riner {

namespace {

// Writes through a temporary file in the target's directory, renamed into place at the end.
template <typename WriteFn>
void write_atomically(const std::filesystem::path& path, WriteFn&& write) {
  io::check_output_path(path);
  util::AtomicFile file(path);
  // A writer names the file it was given, the temporary, and often not why it failed: the
  // message names the target and the system's reason (permission denied, disk full, a name
  // too long) instead.
  const auto told = [&](const std::exception& e, int code) {
    std::string what = e.what();
    const std::string temp = file.temp_path().string();
    if (const std::size_t at = what.find(temp); at != std::string::npos) {
      what.replace(at, temp.size(), path.string());
    }
    if (code != 0 && what.find(std::strerror(code)) == std::string::npos) {
      what += std::string(" (") + std::strerror(code) + ")";
    }
    return what;
  };
  errno = 0;
  try {
    write(file.temp_path());
  } catch (const InputError& e) {
    throw InputError(told(e, errno));
  } catch (const Error& e) {
    throw Error(told(e, errno));
  }
  file.commit();
}

ArrayFile array_file(Array array, FileFormat format, std::string dtype = "float32") {
  ArrayFile f;
  f.array = std::move(array);
  f.format = format;
  f.dtype = std::move(dtype);
  f.non_finite = compute_stats(f.array).non_finite();
  return f;
}

}  // namespace

FileFormat format_from_path(const std::filesystem::path& path) {
  if (split_hdf5_dataset(path)) return FileFormat::kHdf5;
  const std::string ext = io::lower_extension(path);
  if (ext == ".npy") return FileFormat::kNpy;
  if (ext == ".nii") return FileFormat::kNifti;
  if (ext == ".tif" || ext == ".tiff") return FileFormat::kTiff;
  if (ext == ".raw" || ext == ".bin") return FileFormat::kRaw;
  if (ext == ".png") return FileFormat::kPng;
  if (ext == ".json") return FileFormat::kJson;
  if (is_hdf5_path(path)) return FileFormat::kHdf5;
  if (ext == ".gz") {
    throw InputError(io::prefix(path) + "compressed files are not supported; decompress first");
  }
  throw InputError(
      io::prefix(path) + "unknown file type '" + ext +
      "' (riner reads .npy, .nii, .tif/.tiff, .raw/.bin with a .json sidecar, .h5/.nxs)");
}

const char* format_name(FileFormat format) {
  switch (format) {
    case FileFormat::kNpy:
      return "npy";
    case FileFormat::kNifti:
      return "nifti";
    case FileFormat::kTiff:
      return "tiff";
    case FileFormat::kRaw:
      return "raw";
    case FileFormat::kPng:
      return "png";
    case FileFormat::kJson:
      return "json";
    case FileFormat::kHdf5:
      return "hdf5";
  }
  return "unknown";
}

ArrayFile read_array(const std::filesystem::path& path) {
  if (const auto named = split_hdf5_dataset(path)) {
    return array_file(read_hdf5_dataset(named->first, named->second), FileFormat::kHdf5,
                      hdf5_dataset_dtype(named->first, named->second));
  }
  if (io::is_stack_path(path)) return io::read_stack(path, &read_array);
  switch (format_from_path(path)) {
    case FileFormat::kNpy:
      return io::read_npy(path);
    case FileFormat::kNifti:
      return io::read_nifti(path);
    case FileFormat::kTiff:
      return io::read_tiff(path);
    case FileFormat::kRaw:
      return io::read_raw(path);
    case FileFormat::kPng:
      throw InputError(io::prefix(path) + "PNG files are previews; riner does not read them");
    case FileFormat::kJson:
      throw InputError(io::prefix(path) + "is JSON, not an array file");
    case FileFormat::kHdf5:
      if (const std::string volume = hdf5_volume_dataset(path); !volume.empty()) {
        return array_file(read_hdf5_dataset(path, volume), FileFormat::kHdf5,
                          hdf5_dataset_dtype(path, volume));
      }
      {
        TomoFile tomo = read_tomo_file(path);
        return array_file(std::move(tomo.projections), FileFormat::kHdf5, tomo.dtype);
      }
  }
  throw InputError(io::prefix(path) + "unknown file type");
}

ArrayFile read_array_rows(const std::filesystem::path& path, RowRange rows) {
  if (const auto named = split_hdf5_dataset(path)) {
    return array_file(read_hdf5_dataset(named->first, named->second, rows), FileFormat::kHdf5);
  }
  if (io::is_stack_path(path)) return io::read_stack_rows(path, rows);
  std::optional<ArrayFile> file;
  switch (format_from_path(path)) {
    case FileFormat::kNpy:
      file = io::read_npy_rows(path, rows);
      break;
    case FileFormat::kRaw:
      file = io::read_raw_rows(path, rows);
      break;
    case FileFormat::kNifti:
      file = io::read_nifti_rows(path, rows);
      break;
    case FileFormat::kTiff: {
      ArrayFile pages = io::read_tiff_rows(path, rows);
      if (pages.array.rank() != 3) {
        throw InputError(io::prefix(path) + "is one image; reading detector rows needs a stack");
      }
      return pages;
    }
    case FileFormat::kHdf5:
      if (const std::string volume = hdf5_volume_dataset(path); !volume.empty()) {
        return array_file(read_hdf5_dataset(path, volume, rows), FileFormat::kHdf5);
      }
      return array_file(read_tomo_file(path, rows).projections, FileFormat::kHdf5);
    default:
      break;
  }
  if (file) return std::move(*file);
  return io::cut_rows(read_array(path), path, rows);
}

std::vector<std::size_t> read_array_shape(const std::filesystem::path& path) {
  if (const auto named = split_hdf5_dataset(path)) {
    return hdf5_dataset_shape(named->first, named->second);
  }
  if (io::is_stack_path(path)) return io::stack_shape(path);
  switch (format_from_path(path)) {
    case FileFormat::kNpy:
      return io::npy_shape(path);
    case FileFormat::kRaw:
      return io::raw_shape(path);
    case FileFormat::kTiff:
      return io::tiff_shape(path);
    case FileFormat::kHdf5:
      if (const std::string volume = hdf5_volume_dataset(path); !volume.empty()) {
        return hdf5_dataset_shape(path, volume);
      }
      return tomo_file_shape(path);
    case FileFormat::kNifti:
      return io::nifti_shape(path);
    default:
      return read_array(path).array.shape;
  }
}

void write_array(const std::filesystem::path& path, const Array& array,
                 const WriteOptions& options) {
  if (array.shape.empty() || shape_size(array.shape) != array.size()) {
    throw InputError(io::prefix(path) + "array shape " + shape_string(array.shape) +
                     " does not match its " + std::to_string(array.size()) + " values");
  }
  const FileFormat format = format_from_path(path);
  switch (format) {
    case FileFormat::kNpy:
      return write_atomically(path, [&](const auto& tmp) { io::write_npy(tmp, array); });
    case FileFormat::kNifti:
      return write_atomically(
          path, [&](const auto& tmp) { io::write_nifti(tmp, array, options.voxel_size); });
    case FileFormat::kTiff:
      return write_atomically(path, [&](const auto& tmp) {
        io::write_tiff(tmp, array, options.voxel_size.empty() ? 0.0 : options.voxel_size.back());
      });
    case FileFormat::kRaw: {
      std::filesystem::path sidecar = path;
      sidecar += ".json";
      io::check_output_path(sidecar);
      write_atomically(path, [&](const auto& tmp) {
        std::ofstream file(tmp, std::ios::binary);
        file.write(reinterpret_cast<const char*>(array.ptr()),
                   static_cast<std::streamsize>(array.size() * sizeof(float)));
        if (!file.flush()) throw Error(io::prefix(path) + "write failed");
      });
      return write_text(sidecar, io::raw_sidecar_json(array.shape, options.voxel_size));
    }
    case FileFormat::kPng:
      return write_png(path, array);
    case FileFormat::kJson:
      throw InputError(io::prefix(path) + "arrays are not written as JSON");
    case FileFormat::kHdf5: {
      if (array.rank() != 3) {
        throw InputError(io::prefix(path) + "riner writes HDF5 volumes [slices, rows, columns], "
                         "not " + shape_string(array.shape) + "; write images as .npy, .nii or .tif");
      }
      VolumeWriter writer(path.string(), array.shape,
                          options.voxel_size.empty() ? 1.0 : options.voxel_size[0]);
      writer.write(0, array);
      return writer.close();
    }
  }
}

Window percentile_window(const Array& image, double lo_percent, double hi_percent) {
  std::vector<float> finite;
  finite.reserve(image.size());
  for (float v : image.data) {
    if (std::isfinite(v)) finite.push_back(v);
  }
  if (finite.empty()) return {0.0f, 1.0f};
  auto at = [&](double percent) {
    const std::size_t k = std::min(
        finite.size() - 1, static_cast<std::size_t>(percent / 100.0 * (finite.size() - 1) + 0.5));
    std::nth_element(finite.begin(), finite.begin() + k, finite.end());
    return finite[k];
  };
  Window window{at(lo_percent), at(hi_percent)};
  if (!(window.hi > window.lo)) window.hi = window.lo + 1.0f;  // flat image: no division by 0
  return window;
}

Array preview_panel(const Array& axial, const Array& coronal, const Array& sagittal) {
  if (axial.rank() != 2 || coronal.rank() != 2 || sagittal.rank() != 2 ||
      coronal.shape[0] != sagittal.shape[0] || coronal.shape[1] != axial.shape[1] ||
      sagittal.shape[1] != axial.shape[0]) {
    throw InputError("preview planes of shapes " + shape_string(axial.shape) + ", " +
                     shape_string(coronal.shape) + " and " + shape_string(sagittal.shape) +
                     " do not belong to one volume");
  }
  const std::size_t nz = coronal.shape[0], ny = axial.shape[0], nx = axial.shape[1];
  constexpr std::size_t kGap = 4;
  Array panel({std::max(ny, nz), nx + kGap + nx + kGap + ny}, 0.0f);
  for (std::size_t y = 0; y < ny; ++y) {
    for (std::size_t x = 0; x < nx; ++x) panel(y, x) = axial(y, x);
  }
  for (std::size_t z = 0; z < nz; ++z) {
    const std::size_t row = nz - 1 - z;
    for (std::size_t x = 0; x < nx; ++x) panel(row, nx + kGap + x) = coronal(z, x);
    for (std::size_t y = 0; y < ny; ++y) panel(row, 2 * (nx + kGap) + y) = sagittal(z, y);
  }
  return panel;
}

Array coronal_plane(const Array& volume, std::size_t y) {
  const std::size_t nz = volume.shape[0], ny = volume.shape[1], nx = volume.shape[2];
  Array plane({nz, nx});
  for (std::size_t z = 0; z < nz; ++z) {
    for (std::size_t x = 0; x < nx; ++x) plane(z, x) = volume.data[(z * ny + y) * nx + x];
  }
  return plane;
}

Array sagittal_plane(const Array& volume, std::size_t x) {
  const std::size_t nz = volume.shape[0], ny = volume.shape[1], nx = volume.shape[2];
  Array plane({nz, ny});
  for (std::size_t z = 0; z < nz; ++z) {
    for (std::size_t y = 0; y < ny; ++y) plane(z, y) = volume.data[(z * ny + y) * nx + x];
  }
  return plane;
}

// 2D: the image. 3D: the three central slices side by side (preview_panel).
Array preview_image(const Array& image) {
  if (image.rank() == 2) return image;
  if (image.rank() != 3) {
    throw InputError("a preview needs a 2D image or a 3D volume, not rank " +
                     std::to_string(image.rank()));
  }
  return preview_panel(axial_slice(image, image.shape[0] / 2),
                       coronal_plane(image, image.shape[1] / 2),
                       sagittal_plane(image, image.shape[2] / 2));
}

void write_png(const std::filesystem::path& path, const Array& image, const Window& window) {
  const Array slice = preview_image(image);
  const float scale = 255.0f / (window.hi - window.lo);
  std::vector<unsigned char> pixels(slice.size());
  for (std::size_t i = 0; i < slice.size(); ++i) {
    const float v = slice.data[i];
    // Non-finite values show as black: a preview must never hide them as mid-grey.
    const float g = std::isfinite(v) ? (v - window.lo) * scale : 0.0f;
    pixels[i] = static_cast<unsigned char>(std::clamp(g, 0.0f, 255.0f) + 0.5f);
  }
  write_atomically(path, [&](const auto& tmp) {
    io::write_png_gray8(tmp, pixels, slice.shape[0], slice.shape[1]);
  });
}

void write_png(const std::filesystem::path& path, const Array& image) {
  write_png(path, image, percentile_window(preview_image(image)));
}

void write_png_rgb(const std::filesystem::path& path, const std::vector<unsigned char>& rgb,
                   std::size_t rows, std::size_t cols) {
  if (rgb.size() != rows * cols * 3)
    throw InputError(io::prefix(path) + "RGB buffer size mismatch");
  write_atomically(path, [&](const auto& tmp) { io::write_png_rgb8(tmp, rgb, rows, cols); });
}

void write_text(const std::filesystem::path& path, std::string_view text) {
  write_atomically(path, [&](const auto& tmp) {
    std::ofstream file(tmp, std::ios::binary);
    file.write(text.data(), static_cast<std::streamsize>(text.size()));
    if (!file.flush()) throw Error(io::prefix(path) + "write failed");
  });
}

std::string read_text(const std::filesystem::path& path) { return io::read_file_bytes(path); }

}  // namespace riner
