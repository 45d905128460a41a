// Writes small HDF5 files for tests (riner itself only reads HDF5).
#pragma once

#include <hdf5.h>

#include <filesystem>
#include <string>
#include <vector>

namespace riner::test {

class Hdf5Writer {
 public:
  explicit Hdf5Writer(const std::filesystem::path& path)
      : file_(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT)) {}
  ~Hdf5Writer() { H5Fclose(file_); }
  Hdf5Writer(const Hdf5Writer&) = delete;
  Hdf5Writer& operator=(const Hdf5Writer&) = delete;

  // A dataset at `path` (parent groups created), stored as `file_type`.
  template <typename T>
  void write(const std::string& path, const std::vector<hsize_t>& shape, const std::vector<T>& v,
             hid_t file_type) {
    const hid_t link = H5Pcreate(H5P_LINK_CREATE);
    H5Pset_create_intermediate_group(link, 1);
    const hid_t space = H5Screate_simple(static_cast<int>(shape.size()), shape.data(), nullptr);
    const hid_t set =
        H5Dcreate2(file_, path.c_str(), file_type, space, link, H5P_DEFAULT, H5P_DEFAULT);
    H5Dwrite(set, memory_type<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Dclose(set);
    H5Sclose(space);
    H5Pclose(link);
  }

 private:
  template <typename T>
  static hid_t memory_type() {
    if constexpr (std::is_same_v<T, float>) return H5T_NATIVE_FLOAT;
    if constexpr (std::is_same_v<T, double>) return H5T_NATIVE_DOUBLE;
    if constexpr (std::is_same_v<T, std::uint16_t>) return H5T_NATIVE_USHORT;
    return H5T_NATIVE_INT;
  }
  hid_t file_;
};

}  // namespace riner::test
