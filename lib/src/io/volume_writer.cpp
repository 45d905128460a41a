#include "riner/volume_writer.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <optional>
#include <stdexcept>

#include "io/file_access.hpp"
#include "io/formats.hpp"
#include "io/hdf5_volume.hpp"
#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/tomo_file.hpp"
#include "util/atomic_file.hpp"

namespace riner {

class VolumeWriter::Sink {
 public:
  virtual ~Sink() = default;
  virtual void write(std::size_t first_slice, const Array& slices) = 0;
  virtual void close() = 0;
};

namespace {

// .npy, .nii and .raw: a header, then the slices in C order; each block goes to its offset.
class FlatFileSink : public VolumeWriter::Sink {
 public:
  FlatFileSink(const std::filesystem::path& path, const std::string& header, std::size_t bytes)
      : file_(path), header_size_(header.size()) {
    fd_ = ::open(file_.temp_path().c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd_ < 0) throw Error(io::prefix(path) + "cannot create: " + std::strerror(errno));
    put(header.data(), header.size(), 0);
    if (::ftruncate(fd_, static_cast<off_t>(header.size() + bytes)) != 0) {
      throw Error(io::prefix(path) + "cannot reserve " + std::to_string(bytes) +
                  " bytes: " + std::strerror(errno));
    }
  }
  ~FlatFileSink() override {
    if (fd_ >= 0) ::close(fd_);
  }
  void write(std::size_t first_slice, const Array& slices) override {
    const std::size_t slice = slices.shape[1] * slices.shape[2] * sizeof(float);
    put(slices.ptr(), slices.size() * sizeof(float), header_size_ + first_slice * slice);
  }
  void close() override {
    const int fd = fd_;
    fd_ = -1;
    if (::fsync(fd) != 0 || ::close(fd) != 0) {
      throw Error(io::prefix(file_.target()) + "write failed: " + std::strerror(errno));
    }
    file_.commit();
  }

 private:
  void put(const void* data, std::size_t bytes, std::size_t offset) {
    const char* p = static_cast<const char*>(data);
    while (bytes > 0) {
      const ssize_t n = ::pwrite(fd_, p, bytes, static_cast<off_t>(offset));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        throw Error(io::prefix(file_.target()) + "write failed: " + std::strerror(errno));
      }
      p += n;
      bytes -= static_cast<std::size_t>(n);
      offset += static_cast<std::size_t>(n);
    }
  }

  util::AtomicFile file_;
  std::size_t header_size_;
  int fd_ = -1;
};

// `temp`, a copy of `target` where that exists (InputError where it is no HDF5 file).
const std::filesystem::path& copy_of_existing(const std::filesystem::path& target,
                                              const std::filesystem::path& temp) {
  if (!std::filesystem::exists(target)) return temp;
  if (!io::is_hdf5_file(target)) {
    throw InputError(io::prefix(target) +
                     "is there already and is no HDF5 file: refusing to replace it");
  }
  std::error_code error;
  std::filesystem::copy_file(target, temp, std::filesystem::copy_options::overwrite_existing,
                             error);
  if (error) {
    throw Error(io::prefix(target) + "cannot copy it to add the dataset (" + error.message() + ")");
  }
  return temp;
}

class Hdf5Sink : public VolumeWriter::Sink {
 public:
  // A file that is there already keeps what it holds: the dataset is added to a copy of it,
  // which replaces it when complete (before: the whole file was replaced, a Data Exchange
  // scan's projections, flats and darks with it).
  Hdf5Sink(const std::filesystem::path& path, const std::string& dataset,
           const std::vector<std::size_t>& shape, double voxel_mm)
      : file_(path),
        volume_(copy_of_existing(path, file_.temp_path()), dataset, shape, voxel_mm,
                std::filesystem::exists(path)) {}
  void write(std::size_t first_slice, const Array& slices) override {
    volume_.write(first_slice, slices);
  }
  void close() override {
    volume_.close();
    file_.commit();
  }

 private:
  util::AtomicFile file_;
  io::Hdf5VolumeFile volume_;
};

// A multi-page TIFF: libtiff appends pages, so blocks come in order.
class TiffSink : public VolumeWriter::Sink {
 public:
  TiffSink(const std::filesystem::path& path, const std::vector<std::size_t>& shape,
           double voxel_mm)
      : file_(path), pages_(file_.temp_path(), shape[0], shape[1], shape[2], voxel_mm) {}
  void write(std::size_t first_slice, const Array& slices) override {
    if (first_slice != next_) {
      throw std::invalid_argument(io::prefix(file_.target()) +
                                  "a TIFF volume is written in order: slice " +
                                  std::to_string(next_) + " comes next, not " +
                                  std::to_string(first_slice));
    }
    const std::size_t slice = slices.shape[1] * slices.shape[2];
    for (std::size_t k = 0; k < slices.shape[0]; ++k) pages_.append(slices.ptr() + k * slice);
    next_ += slices.shape[0];
  }
  void close() override {
    pages_.close();
    file_.commit();
  }

 private:
  util::AtomicFile file_;
  io::TiffPageWriter pages_;
  std::size_t next_ = 0;
};

class FolderSink : public VolumeWriter::Sink {
 public:
  FolderSink(std::filesystem::path folder, double voxel_mm)
      : folder_(std::move(folder)), voxel_mm_(voxel_mm) {
    write_text(folder_ / VolumeWriter::kUnfinishedMarker,
               "riner is writing this folder's slices, or was stopped before the last: it is no "
               "volume until this file is gone. Run the command again to replace them.\n");
  }
  void write(std::size_t first_slice, const Array& slices) override {
    for (std::size_t k = 0; k < slices.shape[0]; ++k) {
      write_array(VolumeWriter::slice_file(folder_, first_slice + k), axial_slice(slices, k),
                  {{voxel_mm_, voxel_mm_}});
    }
  }
  void close() override {
    std::error_code error;
    std::filesystem::remove(folder_ / VolumeWriter::kUnfinishedMarker, error);
    if (error) {
      throw Error((folder_ / VolumeWriter::kUnfinishedMarker).string() +
                  ": cannot remove it, the volume is complete (" + error.message() + ")");
    }
  }

 private:
  std::filesystem::path folder_;
  double voxel_mm_;
};

// The slice files riner wrote into `folder` (slice_NNNNN.tif).
void remove_slices(const std::filesystem::path& folder) {
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("slice_", 0) == 0 && entry.path().extension() == ".tif") {
      std::filesystem::remove(entry.path());
    }
  }
}

std::unique_ptr<VolumeWriter::Sink> open_sink(const std::string& target,
                                              const std::vector<std::size_t>& shape,
                                              double voxel_mm) {
  const std::filesystem::path path = target;
  const std::size_t bytes = shape_size(shape) * sizeof(float);
  if (auto h5 = split_hdf5_dataset(path)) {
    io::check_output_path(h5->first);
    return std::make_unique<Hdf5Sink>(h5->first, h5->second, shape, voxel_mm);
  }
  if (is_hdf5_path(path)) {
    io::check_output_path(path);
    return std::make_unique<Hdf5Sink>(path, "/volume", shape, voxel_mm);
  }
  if (path.extension().empty() || std::filesystem::is_directory(path)) {
    refuse_overwriting_input(path);
    std::filesystem::create_directories(path);
    if (std::filesystem::exists(path / VolumeWriter::kUnfinishedMarker)) {
      remove_slices(path);  // an unfinished volume's, riner's own
    }
    if (std::filesystem::exists(VolumeWriter::slice_file(path, 0))) {
      throw InputError(path.string() + " already holds slices (" +
                       VolumeWriter::slice_file(path, 0).filename().string() +
                       "): name an empty or new folder");
    }
    return std::make_unique<FolderSink>(path, voxel_mm);
  }
  io::check_output_path(path);
  switch (format_from_path(path)) {
    case FileFormat::kNpy:
      return std::make_unique<FlatFileSink>(path, io::npy_header(shape), bytes);
    case FileFormat::kNifti:
      return std::make_unique<FlatFileSink>(
          path, io::nifti_header(path, shape, {voxel_mm, voxel_mm, voxel_mm}), bytes);
    case FileFormat::kRaw: {
      std::filesystem::path sidecar = path;
      sidecar += ".json";
      io::check_output_path(sidecar);
      write_text(sidecar, io::raw_sidecar_json(shape, {voxel_mm, voxel_mm, voxel_mm}));
      return std::make_unique<FlatFileSink>(path, std::string(), bytes);
    }
    case FileFormat::kTiff:
      return std::make_unique<TiffSink>(path, shape, voxel_mm);
    default:
      throw InputError(io::prefix(path) +
                       "a volume is written as .npy, .nii, .raw, .tif, .h5 or a folder of TIFFs");
  }
}

}  // namespace

VolumeWriter::VolumeWriter(const std::string& target, const std::vector<std::size_t>& shape,
                           double voxel_mm)
    : target_(target), shape_(shape) {
  if (shape.size() != 3 || shape_size(shape) == 0) {
    throw InputError(target + ": a volume is [slices, rows, columns] with none empty, not " +
                     shape_string(shape));
  }
  written_.assign(shape[0], false);
  sink_ = open_sink(target, shape, voxel_mm);
}

VolumeWriter::~VolumeWriter() = default;

void VolumeWriter::write(std::size_t first_slice, const Array& slices) {
  if (slices.rank() != 3 || slices.shape[1] != shape_[1] || slices.shape[2] != shape_[2] ||
      first_slice + slices.shape[0] > shape_[0] || slices.size() != shape_size(slices.shape)) {
    throw std::invalid_argument(target_ + ": slices " + shape_string(slices.shape) + " at " +
                                std::to_string(first_slice) + " do not fit the volume " +
                                shape_string(shape_));
  }
  for (std::size_t k = 0; k < slices.shape[0]; ++k) {
    if (written_[first_slice + k]) {
      throw std::invalid_argument(target_ + ": slice " + std::to_string(first_slice + k) +
                                  " written twice");
    }
  }
  sink_->write(first_slice, slices);
  for (std::size_t k = 0; k < slices.shape[0]; ++k) written_[first_slice + k] = true;
}

void VolumeWriter::close() {
  for (std::size_t k = 0; k < written_.size(); ++k) {
    if (!written_[k]) {
      throw Error(target_ + ": slice " + std::to_string(k) + " of " +
                  std::to_string(written_.size()) + " was never written");
    }
  }
  sink_->close();
}

std::filesystem::path VolumeWriter::slice_file(const std::filesystem::path& folder,
                                               std::size_t k) {
  char name[32];
  std::snprintf(name, sizeof(name), "slice_%05zu.tif", k);
  return folder / name;
}

}  // namespace riner
