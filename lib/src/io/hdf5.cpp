// HDF5 through libhdf5's C API: datasets read as float32 (the library converts any integer or
// float type), tomography layouts recognised by their paths.
#include <hdf5.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>

#include "io/file_access.hpp"
#include "io/hdf5_handle.hpp"
#include "io/row_blocks.hpp"
#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/tomo_file.hpp"

namespace riner {

namespace {

using io::Hid;

std::string where(const std::filesystem::path& file, const std::string& dataset) {
  return file.string() + ":" + dataset + ": ";
}

Hid open_file(const std::filesystem::path& path) {
  io::input_file_size(path);
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors come back as return codes
  if (H5Fis_hdf5(path.c_str()) <= 0) throw InputError(io::prefix(path) + "is not an HDF5 file");
  const hid_t id = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (id < 0) throw InputError(io::prefix(path) + "cannot be opened as HDF5");
  register_input(path);
  return Hid(id, H5Fclose);
}

bool exists(const Hid& file, const std::string& path) {
  // Each link along the path must exist before the next is asked about.
  std::size_t at = 1;
  while (at <= path.size()) {
    const std::size_t next = std::min(path.find('/', at), path.size());
    if (H5Lexists(file.get(), path.substr(0, next).c_str(), H5P_DEFAULT) <= 0) return false;
    at = next + 1;
  }
  return true;
}

// A dataset, open, with its shape; InputError naming it when it is missing or not numbers.
struct OpenDataset {
  std::optional<Hid> set;
  std::optional<Hid> space;
  std::vector<hsize_t> dims;
};

OpenDataset open_dataset(const Hid& file, const std::filesystem::path& path,
                         const std::string& dataset) {
  if (!exists(file, dataset)) throw InputError(where(path, dataset) + "no such dataset");
  OpenDataset d;
  d.set.emplace(H5Dopen2(file.get(), dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (!d.set->ok()) throw InputError(where(path, dataset) + "is not a dataset");
  d.space.emplace(H5Dget_space(d.set->get()), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(d.space->get());
  if (rank < 0 || rank > 8) throw InputError(where(path, dataset) + "has an unreadable shape");
  d.dims.resize(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(d.space->get(), d.dims.data(), nullptr);
  Hid type(H5Dget_type(d.set->get()), H5Tclose);
  const H5T_class_t type_class = H5Tget_class(type.get());
  if (type_class != H5T_INTEGER && type_class != H5T_FLOAT) {
    throw InputError(where(path, dataset) + "holds neither integers nor floats");
  }
  return d;
}

// The type a dataset holds on disk, as numpy names it ("uint16", "float32"); riner reads every
// one as float32.
std::string stored_type(const Hid& file, const std::string& dataset) {
  const Hid set(H5Dopen2(file.get(), dataset.c_str(), H5P_DEFAULT), H5Dclose);
  if (!set.ok()) return "unknown";
  const Hid type(H5Dget_type(set.get()), H5Tclose);
  const std::string bits = std::to_string(8 * H5Tget_size(type.get()));
  if (H5Tget_class(type.get()) == H5T_FLOAT) return "float" + bits;
  return (H5Tget_sign(type.get()) == H5T_SGN_NONE ? "uint" : "int") + bits;
}

// The first of a dataset's filters that the library cannot apply ("HDF5 filter 32008
// (bitshuffle)"), or "" when it has them all: a file compressed by a detector's plugin
// (bitshuffle/LZ4 on Eiger detectors) otherwise read as a corrupt file.
std::string missing_filter(const Hid& set) {
  const Hid plist(H5Dget_create_plist(set.get()), H5Pclose);
  if (!plist.ok()) return "";
  const int filters = H5Pget_nfilters(plist.get());
  for (int i = 0; i < filters; ++i) {
    unsigned flags = 0, config = 0;
    std::size_t values = 0;
    char name[80] = "";
    const H5Z_filter_t id = H5Pget_filter2(plist.get(), static_cast<unsigned>(i), &flags, &values,
                                           nullptr, sizeof(name), name, &config);
    if (id >= 0 && H5Zfilter_avail(id) <= 0) {
      return "HDF5 filter " + std::to_string(id) + (name[0] ? " (" + std::string(name) + ")" : "");
    }
  }
  return "";
}

// A dataset's shape and values as float64 or float32; with `rows`, only those of the second
// axis of a [frames, rows, cols] dataset (a hyperslab: the file is read for those alone).
template <typename T>
std::vector<T> read_values(const Hid& file, const std::filesystem::path& path,
                           const std::string& dataset, std::vector<std::size_t>& shape,
                           std::optional<RowRange> rows = std::nullopt) {
  const OpenDataset d = open_dataset(file, path, dataset);
  shape.assign(d.dims.begin(), d.dims.end());
  hid_t file_space = H5S_ALL;
  std::optional<Hid> memory_space;
  if (rows) {
    io::check_row_range(path.string() + ":" + dataset, shape, *rows);
    const hsize_t start[3] = {0, rows->first, 0};
    const hsize_t count[3] = {d.dims[0], rows->count, d.dims[2]};
    if (H5Sselect_hyperslab(d.space->get(), H5S_SELECT_SET, start, nullptr, count, nullptr) < 0) {
      throw InputError(where(path, dataset) + "cannot select rows");
    }
    file_space = d.space->get();
    memory_space.emplace(H5Screate_simple(3, count, nullptr), H5Sclose);
    shape[1] = rows->count;
  }
  std::vector<T> values(shape_size(shape));
  const hid_t memory_type = std::is_same_v<T, double> ? H5T_NATIVE_DOUBLE : H5T_NATIVE_FLOAT;
  if (!values.empty() &&
      H5Dread(d.set->get(), memory_type, memory_space ? memory_space->get() : H5S_ALL, file_space,
              H5P_DEFAULT, values.data()) < 0) {
    if (const std::string filter = missing_filter(*d.set); !filter.empty()) {
      throw InputError(where(path, dataset) + "is compressed with " + filter +
                       ", which this HDF5 library lacks: install its plugin (Debian: "
                       "hdf5-filter-plugin) and set HDF5_PLUGIN_PATH to its folder");
    }
    throw InputError(where(path, dataset) + "read failed (truncated or corrupt file?)");
  }
  return values;
}

Array read_float_array(const Hid& file, const std::filesystem::path& path,
                       const std::string& dataset, std::optional<RowRange> rows = std::nullopt) {
  std::vector<std::size_t> shape;
  std::vector<float> values = read_values<float>(file, path, dataset, shape, rows);
  return Array(std::move(shape), std::move(values));
}

Array require_rank3(Array a, const std::filesystem::path& path, const std::string& dataset) {
  if (a.rank() != 3) {
    throw InputError(where(path, dataset) + "is " + shape_string(a.shape) +
                     "; expected [frames, rows, columns]");
  }
  return a;
}

// Frames of `all` whose key equals `key`, in file order.
Array frames_with_key(const Array& all, const std::vector<double>& keys, int key) {
  const std::size_t frame = all.shape[1] * all.shape[2];
  Array out;
  std::size_t count = 0;
  for (std::size_t f = 0; f < keys.size(); ++f) {
    if (static_cast<int>(keys[f]) != key) continue;
    out.data.insert(out.data.end(), all.data.begin() + static_cast<std::ptrdiff_t>(f * frame),
                    all.data.begin() + static_cast<std::ptrdiff_t>((f + 1) * frame));
    ++count;
  }
  if (count > 0) out.shape = {count, all.shape[1], all.shape[2]};
  return out;
}

// A Data Exchange flat or dark field: [frames, rows, columns], or one frame [rows, columns] as
// some writers store a single one; none where the dataset is missing or holds no frame.
Array exchange_field(const Hid& file, const std::filesystem::path& path, const std::string& dataset,
                     std::optional<RowRange> rows) {
  if (!exists(file, dataset)) return {};
  const OpenDataset d = open_dataset(file, path, dataset);
  if (d.dims.size() == 3 && d.dims[0] == 0) return {};
  if (d.dims.size() == 2) {
    Array frame = read_float_array(file, path, dataset);
    frame.shape.insert(frame.shape.begin(), 1);
    return rows ? detector_rows(frame, *rows) : frame;
  }
  return require_rank3(read_float_array(file, path, dataset, rows), path, dataset);
}

// Where a tomography file keeps its frames: the layout and the datasets.
struct TomoLayout {
  bool data_exchange = false;
  std::string data;
  std::string keys;
  std::string angles;
};

// The angles the file states for its projections, as stored (none where it states none): Data
// Exchange's theta, or NXtomo's rotation angle at the frames keyed 0 (`keys`, one per frame).
std::vector<double> projection_angles(const Hid& file, const std::filesystem::path& path,
                                      const TomoLayout& layout, const std::vector<double>& keys) {
  std::vector<std::size_t> shape;
  if (layout.data_exchange) {
    if (!exists(file, "/exchange/theta")) return {};
    return read_values<double>(file, path, "/exchange/theta", shape);
  }
  if (layout.angles.empty() || !exists(file, layout.angles)) return {};
  const std::vector<double> angles = read_values<double>(file, path, layout.angles, shape);
  if (angles.size() != keys.size()) {
    throw InputError(where(path, layout.angles) + std::to_string(angles.size()) + " angles for " +
                     std::to_string(keys.size()) + " frames");
  }
  std::vector<double> out;
  for (std::size_t f = 0; f < keys.size(); ++f) {
    if (static_cast<int>(keys[f]) == 0) out.push_back(angles[f]);
  }
  return out;
}

// NXtomo's image keys, one per frame of its data.
std::vector<double> image_keys(const Hid& file, const std::filesystem::path& path,
                               const TomoLayout& layout) {
  std::vector<std::size_t> shape;
  return read_values<double>(file, path, layout.keys, shape);
}

TomoFile read_data_exchange(const Hid& file, const std::filesystem::path& path,
                            const TomoLayout& layout, std::optional<RowRange> rows) {
  TomoFile t;
  t.layout = "data exchange";
  t.dtype = stored_type(file, "/exchange/data");
  t.projections =
      require_rank3(read_float_array(file, path, "/exchange/data", rows), path, "/exchange/data");
  t.flats = exchange_field(file, path, "/exchange/data_white", rows);
  t.darks = exchange_field(file, path, "/exchange/data_dark", rows);
  t.angles_deg = projection_angles(file, path, layout, {});
  return t;
}

TomoFile read_nxtomo(const Hid& file, const std::filesystem::path& path, const TomoLayout& layout,
                     std::optional<RowRange> rows) {
  const std::string& data = layout.data;
  const Array all = require_rank3(read_float_array(file, path, data, rows), path, data);
  const std::vector<double> keys = image_keys(file, path, layout);
  if (keys.size() != all.shape[0]) {
    throw InputError(where(path, layout.keys) + std::to_string(keys.size()) + " image keys for " +
                     std::to_string(all.shape[0]) + " frames in " + data);
  }
  TomoFile t;
  t.layout = "nxtomo";
  t.dtype = stored_type(file, data);
  t.projections = frames_with_key(all, keys, 0);
  t.flats = frames_with_key(all, keys, 1);
  t.darks = frames_with_key(all, keys, 2);
  t.frames_left_out =
      static_cast<std::size_t>(std::count_if(keys.begin(), keys.end(), [](double k) {
        return static_cast<int>(k) < 0 || static_cast<int>(k) > 2;
      }));
  double projections_before = 0.0;
  for (double key : keys) {
    if (static_cast<int>(key) == 0) projections_before += 1.0;
    if (static_cast<int>(key) == 1) t.flat_positions.push_back(projections_before - 0.5);
  }
  if (t.projections.shape.empty()) {
    throw InputError(where(path, layout.keys) + "no frame has image_key 0 (a projection)");
  }
  t.angles_deg = projection_angles(file, path, layout, keys);
  return t;
}

}  // namespace

bool is_hdf5_path(const std::filesystem::path& path) {
  const std::string ext = io::lower_extension(path);
  return ext == ".h5" || ext == ".hdf5" || ext == ".hdf" || ext == ".nxs" || ext == ".nx";
}

namespace {

// The names of the links directly under `group` (none when it is not a group).
std::vector<std::string> links_under(const Hid& file, const std::string& group) {
  H5G_info_t info;
  if (H5Gget_info_by_name(file.get(), group.c_str(), &info, H5P_DEFAULT) < 0) return {};
  std::vector<std::string> names;
  for (hsize_t i = 0; i < info.nlinks && i < 64; ++i) {
    char name[256] = "";
    if (H5Lget_name_by_idx(file.get(), group.c_str(), H5_INDEX_NAME, H5_ITER_INC, i, name,
                           sizeof(name), H5P_DEFAULT) > 0) {
      names.emplace_back(name);
    }
  }
  return names;
}

// An NXtomo entry's frames and keys, where `entry` holds them: /entry (the standard), ESRF's
// /entry0000, Diamond's /entry1/tomo_entry. image_key_control, where there is one, also marks
// alignment frames (-1), which image_key counts as projections.
std::optional<TomoLayout> nxtomo_at(const Hid& file, const std::filesystem::path& path,
                                    const std::string& entry) {
  for (const std::string& data : {entry + "/data/data", entry + "/instrument/detector/data"}) {
    if (!exists(file, data)) continue;
    for (const std::string& keys :
         {entry + "/instrument/detector/image_key_control", entry + "/data/image_key_control",
          entry + "/instrument/detector/image_key", entry + "/data/image_key"}) {
      if (exists(file, keys))
        return TomoLayout{false, data, keys, entry + "/sample/rotation_angle"};
    }
    throw InputError(where(path, data) + "has no image_key beside it (NXtomo)");
  }
  return std::nullopt;
}

TomoLayout find_layout(const Hid& file, const std::filesystem::path& path) {
  if (exists(file, "/exchange/data")) return {true, "/exchange/data", "", ""};
  std::vector<std::string> entries = {"/entry", "/entry1"};
  for (const std::string& top : links_under(file, "/")) {
    entries.push_back("/" + top);
    for (const std::string& inner : links_under(file, "/" + top)) {
      entries.push_back("/" + top + "/" + inner);
    }
  }
  for (const std::string& entry : entries) {
    if (std::optional<TomoLayout> layout = nxtomo_at(file, path, entry)) return *layout;
  }
  throw InputError(io::prefix(path) +
                   "holds neither /exchange/data (Data Exchange) nor an NXtomo entry's "
                   "data/data with its image_key; name a dataset as FILE:/path");
}

}  // namespace

TomoFile read_tomo_file(const std::filesystem::path& path, std::optional<RowRange> rows) {
  const Hid file = open_file(path);
  const TomoLayout layout = find_layout(file, path);
  if (layout.data_exchange) return read_data_exchange(file, path, layout, rows);
  return read_nxtomo(file, path, layout, rows);
}

std::vector<double> tomo_file_angles(const std::filesystem::path& path) {
  const Hid file = open_file(path);
  const TomoLayout layout = find_layout(file, path);
  return projection_angles(
      file, path, layout,
      layout.data_exchange ? std::vector<double>{} : image_keys(file, path, layout));
}

std::vector<std::size_t> tomo_file_shape(const std::filesystem::path& path) {
  const Hid file = open_file(path);
  const TomoLayout layout = find_layout(file, path);
  const OpenDataset d = open_dataset(file, path, layout.data);
  std::vector<std::size_t> shape(d.dims.begin(), d.dims.end());
  if (shape.size() != 3) {
    throw InputError(where(path, layout.data) + "is " + shape_string(shape) +
                     "; expected [frames, rows, columns]");
  }
  if (!layout.data_exchange) {
    const std::vector<double> keys = image_keys(file, path, layout);
    shape[0] = static_cast<std::size_t>(
        std::count_if(keys.begin(), keys.end(), [](double k) { return static_cast<int>(k) == 0; }));
  }
  return shape;
}

std::optional<std::pair<std::filesystem::path, std::string>> split_hdf5_dataset(
    const std::filesystem::path& path) {
  const std::string text = path.string();
  for (std::size_t colon = text.find(":/"); colon != std::string::npos;
       colon = text.find(":/", colon + 1)) {
    const std::filesystem::path file = text.substr(0, colon);
    if (is_hdf5_path(file)) return std::make_pair(file, text.substr(colon + 1));
  }
  return std::nullopt;
}

std::string hdf5_dataset_dtype(const std::filesystem::path& path, const std::string& dataset) {
  const Hid file = open_file(path);
  (void)open_dataset(file, path, dataset);  // its errors first
  return stored_type(file, dataset);
}

std::string hdf5_volume_dataset(const std::filesystem::path& path) {
  const Hid file = open_file(path);
  return exists(file, "/volume") && !exists(file, "/exchange/data") ? "/volume" : "";
}

Array read_hdf5_dataset(const std::filesystem::path& path, const std::string& dataset,
                        std::optional<RowRange> rows) {
  const Hid file = open_file(path);
  return read_float_array(file, path, dataset, rows);
}

std::vector<std::size_t> hdf5_dataset_shape(const std::filesystem::path& path,
                                            const std::string& dataset) {
  const Hid file = open_file(path);
  const OpenDataset d = open_dataset(file, path, dataset);
  return std::vector<std::size_t>(d.dims.begin(), d.dims.end());
}

}  // namespace riner
