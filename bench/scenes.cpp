#include "scenes.hpp"

#include <algorithm>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "riner/io.hpp"
#include "riner/phantom.hpp"

namespace riner::bench {

namespace {

const char* const kDefaultData = "../shared/data/deeplesion";

std::string data_dir(const Options& o) { return o.get("data", kDefaultData); }

}  // namespace

bool uses_deeplesion(const Options& o) {
  const std::string dir = data_dir(o);
  if (dir == "builtin") return false;
  if (std::filesystem::is_directory(dir)) return true;
  if (o.extra.count("data") != 0) throw std::runtime_error(dir + " is not a folder (--data)");
  static bool noted = false;
  if (!noted) {
    std::fprintf(stderr, "note: %s not found, using built-in Shepp-Logan scans\n", dir.c_str());
    noted = true;
  }
  return false;
}

RingScene paper_scene(const Options& o, int index, const Projector& projector, RingModel model) {
  RingScene scene;
  Array truth;
  if (uses_deeplesion(o)) {
    const std::filesystem::path path = data_dir(o) + "/slice_" + std::to_string(index) + ".nii";
    if (!std::filesystem::exists(path)) throw std::runtime_error(path.string() + " not found");
    truth = read_array(path).array;
    for (float& v : truth.data) v *= 0.1f;  // 1/cm -> 1/mm (METHOD.md section 4)
    scene.name = "deeplesion/slice_" + std::to_string(index);
  } else {
    // Soft-tissue contrast like the slices (mu up to 0.02 / mm).
    truth = rasterize(shepp_logan(projector.geometry(), 0.02), projector.geometry(), 4);
    scene.name = "shepp-logan/seed_" + std::to_string(index);
  }
  model.seed = static_cast<std::uint64_t>(index + o.get_int("seed-offset", 0));
  if (model.seed != static_cast<std::uint64_t>(index)) {
    scene.name += " (seed " + std::to_string(model.seed) + ")";
  }
  scene.sim = simulate(truth, projector, model);
  return scene;
}

Geometry parallel_half_turn(double offset_px) {
  Geometry g;
  g.type = GeometryType::kParallel2d;
  g.n_u = 367;
  g.pitch_u = 1.0;
  g.offset_u = offset_px;
  g.voxel_mm = 1.0;
  g.volume_shape = {256, 256};
  g.uniform_angles = UniformAngles{360, 0.0, M_PI};
  g.angles = uniform_angles(*g.uniform_angles);
  g.validate();
  return g;
}

RinerConfig config_from(const Options& o) {
  RinerConfig config;
  const std::string c = o.get("config", "");
  if (!c.empty()) {
    if (std::filesystem::exists(c)) {
      std::ifstream f(c);
      config.update_from_json(
          std::string(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()), c);
    } else {
      config.update_from_json(c, "--config");
    }
  }
  if (o.size == "tiny") config.training.steps = 300;
  config.training.steps = o.get_int("steps", config.training.steps);
  // The training seed (the scenes' own seeds come from --seed-offset).
  config.training.seed =
      static_cast<std::uint64_t>(o.get_int("seed", static_cast<int>(config.training.seed)));
  config.engine = parse_engine(o.get("engine", "opencl"));
  config.validate();
  return config;
}

nlohmann::json detector_accuracy(const Array& alpha, const Array& beta, const SimulatedScan& sim,
                                 const std::vector<std::size_t>& reported_dead) {
  const Geometry& g = sim.scan.geometry;
  double alpha_error = 0.0;
  int live = 0, live_off = 0, dead_crossing = 0, dead_flagged = 0, dead_flagged_by_beta = 0;
  nlohmann::json dead = nlohmann::json::array();
  for (std::size_t e = 0; e < alpha.size(); ++e) {
    if (sim.alpha.data[e] > 0.0f) {
      alpha_error += std::fabs(alpha.data[e] - sim.alpha.data[e]);
      ++live;
      live_off += beta.data[e] < 0.5f;
      continue;
    }
    double clean_mean = 0.0;
    for (std::size_t v = 0; v < g.n_views(); ++v) clean_mean += sim.clean(v, e);
    clean_mean /= static_cast<double>(g.n_views());
    const bool by_beta = beta.data[e] < 0.5f;
    const bool flagged =
        by_beta || std::find(reported_dead.begin(), reported_dead.end(), e) != reported_dead.end();
    if (clean_mean >= 0.1) {
      ++dead_crossing;
      dead_flagged += flagged;
      dead_flagged_by_beta += by_beta;
    }
    dead.push_back(
        {{"element", e}, {"beta", beta.data[e]}, {"flagged", flagged}, {"clean_mean", clean_mean}});
  }
  return {{"alpha_mae_live", live > 0 ? alpha_error / live : 0.0},
          {"dead_crossing", dead_crossing},
          {"dead_flagged", dead_flagged},
          {"dead_flagged_by_beta", dead_flagged_by_beta},
          {"live_switched_off", live_off},
          {"dead", dead}};
}

void write_panel_png(const std::string& path, const std::vector<const Array*>& images,
                     const Window& window) {
  const std::size_t ny = images.front()->shape[0];
  const std::size_t nx = images.front()->shape[1];
  Array panel({ny, images.size() * nx});
  for (std::size_t i = 0; i < ny; ++i) {
    for (std::size_t p = 0; p < images.size(); ++p) {
      for (std::size_t k = 0; k < nx; ++k) panel(i, p * nx + k) = (*images[p])(i, k);
    }
  }
  write_png(path, panel, window);
}

}  // namespace riner::bench
