// Raw samples described by a JSON sidecar "<file>.json":
//   {"dtype": "float32", "shape": [views, elements], "byte_order": "little",
//    "offset_bytes": 0, "order": "C"}
// Only dtype and shape are required.
#include <nlohmann/json.hpp>

#include "io/file_access.hpp"
#include "io/formats.hpp"
#include "io/sample_type.hpp"
#include "riner/error.hpp"

namespace riner::io {

namespace {

std::filesystem::path sidecar_path(const std::filesystem::path& path) {
  std::filesystem::path sidecar = path;
  sidecar += ".json";
  return sidecar;
}

}  // namespace

ArrayFile read_raw(const std::filesystem::path& path) {
  const std::filesystem::path sidecar = sidecar_path(path);
  nlohmann::json meta;
  try {
    meta = nlohmann::json::parse(read_file_bytes(sidecar));
  } catch (const nlohmann::json::exception& e) {
    throw InputError(prefix(sidecar) + "invalid JSON: " + e.what());
  }
  auto bad = [&](const std::string& what) { return InputError(prefix(sidecar) + what); };
  if (!meta.is_object()) throw bad("must be a JSON object");
  if (!meta.contains("dtype") || !meta["dtype"].is_string()) throw bad("needs \"dtype\" (string)");
  const auto type = sample_type_from_name(meta["dtype"].get<std::string>());
  if (!type) throw bad("unsupported dtype \"" + meta["dtype"].get<std::string>() + "\"");
  if (!meta.contains("shape") || !meta["shape"].is_array() || meta["shape"].empty()) {
    throw bad("needs \"shape\" (a non-empty list of sizes)");
  }
  std::vector<std::size_t> shape;
  for (const auto& d : meta["shape"]) {
    if (!d.is_number_unsigned() || d.get<std::uint64_t>() == 0) {
      throw bad("\"shape\" entries must be positive integers");
    }
    shape.push_back(d.get<std::size_t>());
  }
  // json::value throws its own type_error on a non-string; name the field instead.
  auto text = [&](const char* key, const char* fallback) {
    if (!meta.contains(key)) return std::string(fallback);
    if (!meta[key].is_string()) throw bad("\"" + std::string(key) + "\" must be a string");
    return meta[key].get<std::string>();
  };
  const std::string order = text("byte_order", "little");
  if (order != "little" && order != "big") throw bad("\"byte_order\" must be little or big");
  const std::string layout = text("order", "C");
  if (layout != "C" && layout != "F") throw bad("\"order\" must be C or F");
  std::size_t offset = 0;
  if (meta.contains("offset_bytes")) {
    if (!meta["offset_bytes"].is_number_unsigned()) throw bad("\"offset_bytes\" must be >= 0");
    offset = meta["offset_bytes"].get<std::size_t>();
  }

  const std::string bytes = read_file_bytes(path);
  const std::size_t count = element_count(path, shape);
  const std::size_t item = sample_bytes(*type);
  if (offset > bytes.size() || count > (bytes.size() - offset) / item) {
    throw InputError(prefix(path) + "sidecar says " + shape_string(shape) + " " +
                     sample_type_name(*type) + " from byte " + std::to_string(offset) +
                     " but the file has " + std::to_string(bytes.size()) + " bytes");
  }
  ArrayFile file;
  file.format = FileFormat::kRaw;
  file.dtype = sample_type_name(*type);
  std::vector<float> data(count);
  file.non_finite = decode_samples(reinterpret_cast<const unsigned char*>(bytes.data()) + offset,
                                   count, *type, order == "little", data.data());
  if (layout == "F" && shape.size() > 1) data = fortran_to_c_order(data, shape);
  file.array = Array(std::move(shape), std::move(data));
  return file;
}

std::string raw_sidecar_json(const Array& array) {
  nlohmann::json meta = {{"dtype", "float32"},
                         {"shape", array.shape},
                         {"byte_order", host_is_little_endian() ? "little" : "big"},
                         {"offset_bytes", 0},
                         {"order", "C"}};
  return meta.dump(1) + "\n";
}

}  // namespace riner::io
