// Raw samples described by a JSON sidecar "<file>.json":
//   {"dtype": "float32", "shape": [views, elements], "byte_order": "little",
//    "offset_bytes": 0, "trailing_bytes": 0, "order": "C"}
// Only dtype and shape are required; the file holds exactly what they say (a footer after the
// samples is named by trailing_bytes), and any other key is refused (a misspelt "endian" read
// byte-swapped samples without a word).
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>

#include "io/file_access.hpp"
#include "io/formats.hpp"
#include "io/row_blocks.hpp"
#include "io/sample_type.hpp"
#include "riner/error.hpp"
#include "util/user_json.hpp"

namespace riner::io {

namespace {

std::filesystem::path sidecar_path(const std::filesystem::path& path) {
  std::filesystem::path sidecar = path;
  sidecar += ".json";
  return sidecar;
}

struct RawLayout {
  SampleType type = SampleType::kFloat32;
  std::vector<std::size_t> shape;
  bool little_endian = true;
  bool fortran_order = false;
  std::size_t offset = 0;
  std::size_t trailing = 0;
  std::vector<double> voxel_size;  // mm per axis, when the sidecar states it
};

bool known_sidecar_key(const std::string& key) {
  for (const char* known : {"dtype", "shape", "byte_order", "order", "offset_bytes",
                            "trailing_bytes", "voxel_size_mm", "comment", "description", "notes"}) {
    if (key == known) return true;
  }
  return !key.empty() && key[0] == '_';
}

RawLayout read_sidecar(const std::filesystem::path& path) {
  const std::filesystem::path sidecar = sidecar_path(path);
  const nlohmann::json meta = util::parse_user_json(read_file_bytes(sidecar), sidecar.string());
  auto bad = [&](const std::string& what) { return InputError(prefix(sidecar) + what); };
  if (!meta.is_object()) throw bad("must be a JSON object");
  for (const auto& [key, value] : meta.items()) {
    if (!known_sidecar_key(key)) {
      throw bad("unknown key \"" + key +
                "\" (a sidecar takes dtype, shape, byte_order, order, offset_bytes, "
                "trailing_bytes, voxel_size_mm; comments as comment, description, notes or a "
                "key starting with _)");
    }
  }
  if (!meta.contains("dtype") || !meta["dtype"].is_string()) throw bad("needs \"dtype\" (string)");
  const auto type = sample_type_from_name(meta["dtype"].get<std::string>());
  if (!type) throw bad("unsupported dtype \"" + meta["dtype"].get<std::string>() + "\"");
  if (!meta.contains("shape") || !meta["shape"].is_array() || meta["shape"].empty()) {
    throw bad("needs \"shape\" (a non-empty list of sizes)");
  }
  RawLayout layout;
  layout.type = *type;
  for (const auto& d : meta["shape"]) {
    if (!d.is_number_unsigned() || d.get<std::uint64_t>() == 0) {
      throw bad("\"shape\" entries must be positive integers");
    }
    layout.shape.push_back(d.get<std::size_t>());
  }
  // json::value throws its own type_error on a non-string; name the field instead.
  auto text = [&](const char* key, const char* fallback) {
    if (!meta.contains(key)) return std::string(fallback);
    if (!meta[key].is_string()) throw bad("\"" + std::string(key) + "\" must be a string");
    return meta[key].get<std::string>();
  };
  const std::string order = text("byte_order", "little");
  if (order != "little" && order != "big") throw bad("\"byte_order\" must be little or big");
  layout.little_endian = order == "little";
  const std::string memory_order = text("order", "C");
  if (memory_order != "C" && memory_order != "F") throw bad("\"order\" must be C or F");
  layout.fortran_order = memory_order == "F";
  if (meta.contains("offset_bytes")) {
    if (!meta["offset_bytes"].is_number_unsigned()) throw bad("\"offset_bytes\" must be >= 0");
    layout.offset = meta["offset_bytes"].get<std::size_t>();
  }
  if (meta.contains("trailing_bytes")) {
    if (!meta["trailing_bytes"].is_number_unsigned()) throw bad("\"trailing_bytes\" must be >= 0");
    layout.trailing = meta["trailing_bytes"].get<std::size_t>();
  }
  if (meta.contains("voxel_size_mm")) {
    const nlohmann::json& sizes = meta["voxel_size_mm"];
    const auto positive = [](const nlohmann::json& v) {
      return v.is_number() && v.get<double>() > 0.0 && std::isfinite(v.get<double>());
    };
    if (!sizes.is_array() || sizes.size() != layout.shape.size() ||
        !std::all_of(sizes.begin(), sizes.end(), positive)) {
      throw bad("\"voxel_size_mm\" must be a positive size in mm per axis of \"shape\"");
    }
    for (const auto& v : sizes) layout.voxel_size.push_back(v.get<double>());
  }
  return layout;
}

void check_file_size(const RawLayout& layout, const std::filesystem::path& path,
                     std::uint64_t bytes) {
  const std::size_t count = element_count(path, layout.shape);
  const std::size_t item = sample_bytes(layout.type);
  if (layout.offset > bytes || count > (bytes - layout.offset) / item) {
    throw InputError(prefix(path) + "sidecar says " + shape_string(layout.shape) + " " +
                     sample_type_name(layout.type) + " from byte " + std::to_string(layout.offset) +
                     " but the file has " + std::to_string(bytes) + " bytes");
  }
  const std::uint64_t described = layout.offset + count * item + layout.trailing;
  if (bytes != described) {
    throw InputError(prefix(path) + "sidecar says " + shape_string(layout.shape) + " " +
                     sample_type_name(layout.type) + " from byte " + std::to_string(layout.offset) +
                     " (" + std::to_string(described) + " bytes) but the file has " +
                     std::to_string(bytes) +
                     ": check dtype and shape (a footer after the samples: \"trailing_bytes\")");
  }
}

}  // namespace

ArrayFile read_raw(const std::filesystem::path& path) {
  const RawLayout layout = read_sidecar(path);
  const std::string bytes = read_file_bytes(path);
  check_file_size(layout, path, bytes.size());
  ArrayFile file;
  file.format = FileFormat::kRaw;
  file.dtype = sample_type_name(layout.type);
  std::vector<float> data(shape_size(layout.shape));
  file.non_finite =
      decode_samples(reinterpret_cast<const unsigned char*>(bytes.data()) + layout.offset,
                     data.size(), layout.type, layout.little_endian, data.data());
  if (layout.fortran_order && layout.shape.size() > 1)
    data = fortran_to_c_order(data, layout.shape);
  file.array = Array(layout.shape, std::move(data));
  file.voxel_size = layout.voxel_size;
  return file;
}

std::vector<std::size_t> raw_shape(const std::filesystem::path& path) {
  const RawLayout layout = read_sidecar(path);
  check_file_size(layout, path, input_file_size(path));
  return layout.shape;
}

std::optional<ArrayFile> read_raw_rows(const std::filesystem::path& path, RowRange rows) {
  const RawLayout layout = read_sidecar(path);
  check_file_size(layout, path, input_file_size(path));
  if (layout.fortran_order || layout.shape.size() != 3) return std::nullopt;
  check_row_range(path, layout.shape, rows);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(prefix(path) + "cannot be opened");
  register_input(path);
  return read_row_blocks(in, path, layout.offset, layout.shape, rows, layout.type,
                         layout.little_endian, FileFormat::kRaw);
}

std::string raw_sidecar_json(const std::vector<std::size_t>& shape,
                             const std::vector<double>& voxel_size) {
  nlohmann::json meta = {{"dtype", "float32"},
                         {"shape", shape},
                         {"byte_order", host_is_little_endian() ? "little" : "big"},
                         {"offset_bytes", 0},
                         {"order", "C"}};
  if (voxel_size.size() == shape.size()) meta["voxel_size_mm"] = voxel_size;
  return meta.dump(1) + "\n";
}

}  // namespace riner::io
