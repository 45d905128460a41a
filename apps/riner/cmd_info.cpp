// riner info FILE: what an array file holds (shape, type, value range, non-finite count), or a
// summary of a geometry file.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_args.hpp"
#include "cli_common.hpp"
#include "commands.hpp"
#include "riner/error.hpp"
#include "riner/geometry.hpp"
#include "riner/io.hpp"

namespace riner::app {

namespace {

nlohmann::json geometry_summary(const Geometry& g) {
  nlohmann::json out = {{"type", geometry_type_name(g.type)},
                        {"views", g.n_views()},
                        {"angle_first_rad", g.angles.front()},
                        {"angle_last_rad", g.angles.back()},
                        {"detector_u", g.n_u},
                        {"pitch_u_mm", g.pitch_u},
                        {"offset_u_px", g.offset_u},
                        {"volume_shape", g.volume_shape},
                        {"voxel_mm", g.voxel_mm},
                        {"measurement_shape", g.measurement_shape()}};
  if (g.is_3d()) {
    out["detector_v"] = g.n_v;
    out["pitch_v_mm"] = g.pitch_v;
    out["offset_v_px"] = g.offset_v;
  }
  if (g.is_divergent()) {
    out["source_origin_mm"] = g.source_origin_mm;
    out["origin_detector_mm"] = g.origin_detector_mm;
  }
  return out;
}

void print_geometry(const std::string& path, const Geometry& g) {
  std::printf("%s: %s geometry\n", path.c_str(), geometry_type_name(g.type));
  std::printf("  views              %zu, %.6g .. %.6g rad (%.3f .. %.3f deg)\n", g.n_views(),
              g.angles.front(), g.angles.back(), g.angles.front() * 180.0 / M_PI,
              g.angles.back() * 180.0 / M_PI);
  if (g.is_3d()) {
    std::printf("  detector           %zu x %zu (u x v), pitch %g x %g mm, offset %g, %g px\n",
                g.n_u, g.n_v, g.pitch_u, g.pitch_v, g.offset_u, g.offset_v);
  } else {
    std::printf("  detector           %zu elements, pitch %g mm, offset %g px\n", g.n_u, g.pitch_u,
                g.offset_u);
  }
  if (g.is_divergent()) {
    std::printf("  source-origin      %g mm, origin-detector %g mm (magnification %.4f)\n",
                g.source_origin_mm, g.origin_detector_mm,
                (g.source_origin_mm + g.origin_detector_mm) / g.source_origin_mm);
  }
  std::printf("  volume             %s voxels of %g mm\n", shape_string(g.volume_shape).c_str(),
              g.voxel_mm);
  std::printf("  expects data       %s\n", shape_string(g.measurement_shape()).c_str());
}

}  // namespace

int run_info(int argc, char** argv, int first) {
  Args args("info", "Describes an array file (.npy, .nii, .tif, .raw) or a geometry file (.json).");
  args.positional("FILE", "the file to describe").output_flags();
  if (!args.parse(argc, argv, first)) return 0;
  const std::string path = args.get("FILE");
  const bool json = args.is_set("json");
  const bool quiet = args.is_set("quiet");

  // A folder or a pattern of TIFFs has no extension of its own: read_array takes it as a stack.
  if (lowercase(std::filesystem::path(path).extension().string()) == ".json" &&
      !std::filesystem::is_directory(path)) {
    const Geometry g = Geometry::load(path);
    if (json) {
      nlohmann::json out = {
          {"file", path}, {"kind", "geometry"}, {"geometry", geometry_summary(g)}};
      std::printf("%s\n", out.dump(1).c_str());
    } else if (!quiet) {
      print_geometry(path, g);
    }
    return 0;
  }

  const ArrayFile file = read_array(path);
  const ArrayStats stats = compute_stats(file.array);
  // Without a finite value there is no minimum, maximum, mean or spread (not 0).
  const auto over_finite = [&](double v) {
    return stats.finite > 0 ? nlohmann::json(v) : nlohmann::json(nullptr);
  };
  if (json) {
    nlohmann::json out = {{"file", path},
                          {"kind", "array"},
                          {"format", format_name(file.format)},
                          {"dtype", file.dtype},
                          {"shape", file.array.shape},
                          {"min", over_finite(stats.min)},
                          {"max", over_finite(stats.max)},
                          {"mean", over_finite(stats.mean)},
                          {"stddev", over_finite(stats.stddev)},
                          {"finite", stats.finite},
                          {"nan", stats.nan},
                          {"pos_inf", stats.pos_inf},
                          {"neg_inf", stats.neg_inf}};
    if (!file.voxel_size.empty()) out["voxel_size"] = file.voxel_size;
    std::printf("%s\n", out.dump(1).c_str());
  } else if (!quiet) {
    std::printf("%s: %s %s %s\n", path.c_str(), format_name(file.format), file.dtype.c_str(),
                shape_string(file.array.shape).c_str());
    if (stats.finite > 0) {
      std::printf("  min %.6g  max %.6g  mean %.6g  std %.6g (over %zu finite values)\n", stats.min,
                  stats.max, stats.mean, stats.stddev, stats.finite);
    } else {
      std::printf("  no finite value\n");
    }
    std::printf("  non-finite         %zu (NaN %zu, +inf %zu, -inf %zu)\n", stats.non_finite(),
                stats.nan, stats.pos_inf, stats.neg_inf);
    if (!file.voxel_size.empty()) {
      std::string v;
      for (double s : file.voxel_size) v += (v.empty() ? "" : " x ") + std::to_string(s);
      std::printf("  voxel size         %s\n", v.c_str());
    }
  }
  return 0;
}

}  // namespace riner::app
