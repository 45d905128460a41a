// The scan-contract geometry file (METHOD.md §3): parsing with a precise message for every bad
// field, validation, and writing back in the same form.
#include <cmath>
#include <initializer_list>
#include <nlohmann/json.hpp>

#include "riner/error.hpp"
#include "riner/geometry.hpp"
#include "riner/io.hpp"
#include "util/user_json.hpp"

namespace riner {

namespace {

using nlohmann::json;

class Parser {
 public:
  explicit Parser(std::string_view source) : source_(source) {}

  [[noreturn]] void fail(const std::string& field, const std::string& what) const {
    throw InputError(source_ + ": " + field + " " + what);
  }

  const json& member(const json& object, const std::string& key, const std::string& field) const {
    if (!object.contains(key)) fail(field, "is missing");
    return object.at(key);
  }

  double number(const json& value, const std::string& field) const {
    if (!value.is_number()) fail(field, "must be a number");
    const double v = value.get<double>();
    if (!std::isfinite(v)) fail(field, "must be finite");
    return v;
  }

  double positive(const json& value, const std::string& field) const {
    const double v = number(value, field);
    if (!(v > 0.0)) fail(field, "must be > 0 (got " + format(v) + ")");
    return v;
  }

  std::size_t count(const json& value, const std::string& field) const {
    if (!value.is_number_integer() && !(value.is_number() && is_whole(value.get<double>()))) {
      fail(field, "must be a positive integer");
    }
    const double v = value.get<double>();
    if (v < 1.0) fail(field, "must be >= 1 (got " + format(v) + ")");
    if (v > 1e7) fail(field, "is absurdly large (" + format(v) + ")");
    return static_cast<std::size_t>(v);
  }

  // A misspelt field ("center_z_mm", "offset") would otherwise be left out without a word:
  // every key is one the object takes, or documentation ("comment", "description", "notes",
  // or a name starting with '_').
  void known_keys(const json& object, const std::string& field,
                  std::initializer_list<const char*> keys) const {
    for (const auto& [key, value] : object.items()) {
      if (key.empty() || key[0] == '_' || key == "comment" || key == "description" ||
          key == "notes") {
        continue;
      }
      bool known = false;
      std::string list;
      for (const char* k : keys) {
        known = known || key == k;
        list += (list.empty() ? "" : ", ") + std::string(k);
      }
      if (!known) {
        fail((field.empty() ? "" : field + ".") + key,
             "is not a geometry field (" + (field.empty() ? std::string("the file") : field) +
                 " takes " + list + ")");
      }
    }
  }

  // A scalar in 2D, an [u, v] pair in 3D.
  std::vector<json> per_axis(const json& value, bool is_3d, const std::string& field) const {
    if (is_3d) {
      if (!value.is_array() || value.size() != 2) fail(field, "must be a pair [u, v] in 3D");
      return {value[0], value[1]};
    }
    if (value.is_array()) fail(field, "must be a single value in 2D");
    return {value};
  }

 private:
  static bool is_whole(double v) { return std::isfinite(v) && v == std::floor(v); }
  static std::string format(double v) {
    std::string s = std::to_string(v);
    s.erase(s.find_last_not_of('0') + 1);
    if (!s.empty() && s.back() == '.') s.pop_back();
    return s;
  }
  std::string source_;
};

GeometryType parse_type(const std::string& name, const Parser& p) {
  if (name == "parallel2d") return GeometryType::kParallel2d;
  if (name == "fan2d") return GeometryType::kFan2d;
  if (name == "cone3d") return GeometryType::kCone3d;
  if (name == "parallel3d") return GeometryType::kParallel3d;
  p.fail("type", "must be one of parallel2d, fan2d, cone3d, parallel3d (got \"" + name + "\")");
}

}  // namespace

const char* geometry_type_name(GeometryType type) {
  switch (type) {
    case GeometryType::kParallel2d:
      return "parallel2d";
    case GeometryType::kFan2d:
      return "fan2d";
    case GeometryType::kCone3d:
      return "cone3d";
    case GeometryType::kParallel3d:
      return "parallel3d";
  }
  return "unknown";
}

std::vector<double> uniform_angles(const UniformAngles& spec) {
  std::vector<double> angles(spec.count);
  for (std::size_t i = 0; i < spec.count; ++i) {
    angles[i] =
        spec.start_rad + spec.range_rad * static_cast<double>(i) / static_cast<double>(spec.count);
  }
  return angles;
}

Geometry Geometry::from_json(std::string_view json_text, std::string_view source) {
  const Parser p(source);
  const json root = util::parse_user_json(json_text, std::string(source));
  if (!root.is_object()) p.fail("top level", "must be a JSON object");

  // "files": a scan JSON is its geometry with the files it names (riner/scan.hpp).
  p.known_keys(root, "",
               {"type", "detector", "source_origin_mm", "origin_detector_mm", "angles",
                "angles_rad", "volume", "files"});
  Geometry g;
  const json& type = p.member(root, "type", "type");
  if (!type.is_string()) p.fail("type", "must be a string");
  g.type = parse_type(type.get<std::string>(), p);
  const bool is_3d = g.is_3d();

  const json& detector = p.member(root, "detector", "detector");
  if (!detector.is_object()) p.fail("detector", "must be an object");
  p.known_keys(detector, "detector", {"count", "pitch_mm", "offset_px"});
  auto counts = p.per_axis(p.member(detector, "count", "detector.count"), is_3d, "detector.count");
  g.n_u = p.count(counts[0], "detector.count");
  if (is_3d) g.n_v = p.count(counts[1], "detector.count[1]");
  auto pitches =
      p.per_axis(p.member(detector, "pitch_mm", "detector.pitch_mm"), is_3d, "detector.pitch_mm");
  g.pitch_u = p.positive(pitches[0], "detector.pitch_mm");
  if (is_3d) g.pitch_v = p.positive(pitches[1], "detector.pitch_mm[1]");
  if (detector.contains("offset_px")) {
    auto offsets = p.per_axis(detector["offset_px"], is_3d, "detector.offset_px");
    g.offset_u = p.number(offsets[0], "detector.offset_px");
    if (is_3d) g.offset_v = p.number(offsets[1], "detector.offset_px[1]");
  }

  if (g.is_divergent()) {
    g.source_origin_mm =
        p.positive(p.member(root, "source_origin_mm", "source_origin_mm"), "source_origin_mm");
    g.origin_detector_mm = p.positive(p.member(root, "origin_detector_mm", "origin_detector_mm"),
                                      "origin_detector_mm");
  } else {
    // A parallel beam has no source: distances given with it are another geometry's (a fan
    // or cone beam's type forgotten?), not to be dropped without a word.
    for (const char* key : {"source_origin_mm", "origin_detector_mm"}) {
      if (root.contains(key)) {
        p.fail(key,
               "belongs to a fan or cone beam (type \"fan2d\" or \"cone3d\"); a parallel beam has "
               "none");
      }
    }
  }

  const bool has_uniform = root.contains("angles");
  const bool has_list = root.contains("angles_rad");
  if (has_uniform == has_list)
    p.fail("angles", "must be given once: either \"angles\" or \"angles_rad\"");
  if (has_uniform) {
    const json& a = root["angles"];
    if (!a.is_object()) p.fail("angles", "must be an object {count, start_rad, range_rad}");
    p.known_keys(a, "angles", {"count", "start_rad", "range_rad"});
    UniformAngles spec;
    spec.count = p.count(p.member(a, "count", "angles.count"), "angles.count");
    spec.start_rad = a.contains("start_rad") ? p.number(a["start_rad"], "angles.start_rad") : 0.0;
    spec.range_rad = p.number(p.member(a, "range_rad", "angles.range_rad"), "angles.range_rad");
    if (spec.range_rad == 0.0 && spec.count > 1) p.fail("angles.range_rad", "must not be 0");
    g.uniform_angles = spec;
    g.angles = riner::uniform_angles(spec);
  } else {
    const json& list = root["angles_rad"];
    if (!list.is_array() || list.empty()) p.fail("angles_rad", "must be a non-empty list");
    for (std::size_t i = 0; i < list.size(); ++i) {
      g.angles.push_back(p.number(list[i], "angles_rad[" + std::to_string(i) + "]"));
    }
  }

  const json& volume = p.member(root, "volume", "volume");
  if (!volume.is_object()) p.fail("volume", "must be an object");
  p.known_keys(volume, "volume", {"shape", "voxel_mm", "centre_z_mm"});
  const json& shape = p.member(volume, "shape", "volume.shape");
  const std::size_t rank = is_3d ? 3 : 2;
  if (!shape.is_array() || shape.size() != rank) {
    p.fail("volume.shape", is_3d ? "must be [n_z, n_y, n_x] for a 3D geometry"
                                 : "must be [n_y, n_x] for a 2D geometry");
  }
  for (std::size_t i = 0; i < rank; ++i) {
    g.volume_shape.push_back(p.count(shape[i], "volume.shape[" + std::to_string(i) + "]"));
  }
  g.voxel_mm = p.positive(p.member(volume, "voxel_mm", "volume.voxel_mm"), "volume.voxel_mm");
  if (volume.contains("centre_z_mm")) {
    g.grid_centre_z_mm = p.number(volume["centre_z_mm"], "volume.centre_z_mm");
  }
  try {
    g.validate();
  } catch (const InputError& e) {
    throw InputError(std::string(source) + ": " + e.what());
  }
  return g;
}

Geometry Geometry::load(const std::filesystem::path& path) {
  return from_json(read_text(path), path.string());
}

std::string Geometry::to_json() const {
  json root;
  root["type"] = geometry_type_name(type);
  if (is_3d()) {
    root["detector"] = {{"count", {n_u, n_v}},
                        {"pitch_mm", {pitch_u, pitch_v}},
                        {"offset_px", {offset_u, offset_v}}};
  } else {
    root["detector"] = {{"count", n_u}, {"pitch_mm", pitch_u}, {"offset_px", offset_u}};
  }
  if (is_divergent()) {
    root["source_origin_mm"] = source_origin_mm;
    root["origin_detector_mm"] = origin_detector_mm;
  }
  if (uniform_angles && riner::uniform_angles(*uniform_angles) == angles) {
    root["angles"] = {{"count", uniform_angles->count},
                      {"start_rad", uniform_angles->start_rad},
                      {"range_rad", uniform_angles->range_rad}};
  } else {
    root["angles_rad"] = angles;
  }
  root["volume"] = {{"shape", volume_shape}, {"voxel_mm", voxel_mm}};
  if (grid_centre_z_mm != 0.0) root["volume"]["centre_z_mm"] = grid_centre_z_mm;
  return root.dump(1) + "\n";
}

void Geometry::save(const std::filesystem::path& path) const { write_text(path, to_json()); }

}  // namespace riner
