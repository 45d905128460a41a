#include "io/hdf5_volume.hpp"

#include <optional>

#include "io/hdf5_handle.hpp"
#include "riner/error.hpp"

namespace riner::io {

struct Hdf5VolumeFile::Handles {
  std::optional<Hid> file, set;
};

namespace {

// Whether `path` ("a/b/c") names a link in the file; H5Lexists fails where a group on the way
// is missing, so each step is asked in turn.
bool link_exists(hid_t file, const std::string& path) {
  std::size_t end = 0;
  while (end != std::string::npos) {
    end = path.find('/', end + 1);
    const std::string part = path.substr(0, end);
    if (part.empty() || part == "/") continue;
    if (H5Lexists(file, part.c_str(), H5P_DEFAULT) <= 0) return false;
  }
  return true;
}

}  // namespace

bool is_hdf5_file(const std::filesystem::path& path) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  return H5Fis_hdf5(path.c_str()) > 0;
}

Hdf5VolumeFile::Hdf5VolumeFile(const std::filesystem::path& file, const std::string& dataset,
                               const std::vector<std::size_t>& shape, double voxel_mm,
                               bool add_to_file)
    : handles_(std::make_unique<Handles>()), where_(file.string() + ":" + dataset + ": ") {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  if (add_to_file) {
    handles_->file.emplace(H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
    if (!handles_->file->ok()) throw InputError(where_ + "cannot open the HDF5 file to add to it");
    if (link_exists(handles_->file->get(), dataset) &&
        H5Ldelete(handles_->file->get(), dataset.c_str(), H5P_DEFAULT) < 0) {
      throw Error(where_ + "cannot replace the dataset already there");
    }
  } else {
    handles_->file.emplace(H5Fcreate(file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT),
                           H5Fclose);
  }
  if (!handles_->file->ok()) throw Error(where_ + "cannot create the HDF5 file");
  const hsize_t dims[3] = {shape[0], shape[1], shape[2]};
  const hsize_t chunk[3] = {1, shape[1], shape[2]};
  Hid space(H5Screate_simple(3, dims, nullptr), H5Sclose);
  Hid links(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(links.get(), 1);
  Hid layout(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  H5Pset_chunk(layout.get(), 3, chunk);
  handles_->set.emplace(H5Dcreate2(handles_->file->get(), dataset.c_str(), H5T_IEEE_F32LE,
                                   space.get(), links.get(), layout.get(), H5P_DEFAULT),
                        H5Dclose);
  if (!handles_->set->ok()) throw Error(where_ + "cannot create the dataset");
  const hsize_t three = 3;
  Hid scalar_space(H5Screate_simple(1, &three, nullptr), H5Sclose);
  Hid attribute(H5Acreate2(handles_->set->get(), "voxel_size_mm", H5T_IEEE_F64LE,
                           scalar_space.get(), H5P_DEFAULT, H5P_DEFAULT),
                H5Aclose);
  const double sizes[3] = {voxel_mm, voxel_mm, voxel_mm};
  if (!attribute.ok() || H5Awrite(attribute.get(), H5T_NATIVE_DOUBLE, sizes) < 0) {
    throw Error(where_ + "cannot write its voxel size");
  }
}

Hdf5VolumeFile::~Hdf5VolumeFile() = default;

void Hdf5VolumeFile::write(std::size_t first_slice, const Array& slices) {
  Hid space(H5Dget_space(handles_->set->get()), H5Sclose);
  const hsize_t start[3] = {first_slice, 0, 0};
  const hsize_t count[3] = {slices.shape[0], slices.shape[1], slices.shape[2]};
  Hid memory(H5Screate_simple(3, count, nullptr), H5Sclose);
  if (H5Sselect_hyperslab(space.get(), H5S_SELECT_SET, start, nullptr, count, nullptr) < 0 ||
      H5Dwrite(handles_->set->get(), H5T_NATIVE_FLOAT, memory.get(), space.get(), H5P_DEFAULT,
               slices.ptr()) < 0) {
    throw Error(where_ + "writing slices " + std::to_string(first_slice) + ".." +
                std::to_string(first_slice + slices.shape[0]) + " failed (disk full?)");
  }
}

void Hdf5VolumeFile::close() {
  const bool set_ok = handles_->set->close();
  if (!set_ok || H5Fflush(handles_->file->get(), H5F_SCOPE_LOCAL) < 0 ||
      !handles_->file->close()) {
    throw Error(where_ + "the HDF5 file could not be completed (disk full?)");
  }
}

}  // namespace riner::io
