// Skipping the air (model/occupancy.hpp) on its own: the share of the grid kept, what each of
// its checks kept, the rays through the skipped air, its time, and with a ground truth the
// object voxels it would skip, with the centre of rotation shifted by each of --shifts (issue 29:
// robust to a centre a few pixels off).
//
//   riner_bench --case=air_carving --scan=SINO.npy [--truth=GROUND_TRUTH.nii] [--shifts=0,-5,5]
//               [--config=JSON] [--json=FILE]
// The scan's geometry is the geometry.json beside it; the settings are the config's
// (training.air_*). The carving's FBP check runs on the reference engine when --config says
// "engine": "reference", else on the device.
#include <chrono>
#include <cstdio>
#include <sstream>

#include "harness.hpp"
#include "model/occupancy.hpp"
#include "riner/error.hpp"
#include "riner/io.hpp"
#include "riner/scan.hpp"
#include "scenes.hpp"

namespace {

using riner::bench::Options;
using riner::bench::Result;

std::vector<double> shifts_from(const std::string& text) {
  std::vector<double> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    try {
      out.push_back(std::stod(item));
    } catch (const std::exception&) {
      throw riner::InputError("--shifts takes numbers separated by commas (got '" + item + "')");
    }
  }
  return out;
}

std::vector<Result> air_carving(const Options& o) {
  const std::string scan_path = o.get("scan", "../shared/data/neutron360/sino.npy");
  const std::string truth_path = o.get("truth", "");
  const riner::Scan scan = riner::load_scan(scan_path);
  const riner::Array truth =
      truth_path.empty() ? riner::Array() : riner::read_array(truth_path).array;
  const riner::RinerConfig config = riner::bench::config_from(o);
  const riner::model::OccupancySettings settings = riner::model::occupancy_settings(
      config.training, scan.geometry, config.engine,
      config.engine == riner::Engine::kOpenCL ? std::optional(riner::Device::open(o.device))
                                              : std::nullopt);
  std::vector<Result> rows;
  for (double shift : shifts_from(o.get("shifts", "0"))) {
    riner::Scan shifted = scan;
    shifted.geometry.offset_u += shift;
    const auto start = std::chrono::steady_clock::now();
    const riner::model::Occupancy occupancy = riner::model::carve_occupancy(shifted, settings);
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    long lost = -1;
    if (!truth.data.empty()) {
      if (truth.shape != scan.geometry.volume_shape)
        throw riner::InputError(truth_path + " is not on the scan's grid");
      lost = 0;
      for (std::size_t i = 0; i < truth.size(); ++i)
        lost += truth.data[i] > 0.0f && !occupancy.inside[i];
    }
    nlohmann::json fields = {{"scan", scan_path},
                             {"shift_px", shift},
                             {"carved", occupancy.carved},
                             {"grid_fraction_kept", occupancy.inside_fraction},
                             {"outlier_views", occupancy.outlier_views},
                             {"kept_by_fbp", occupancy.kept_by_fbp},
                             {"skipped_rays", occupancy.skipped_rays},
                             {"skipped_ray_largest_sigmas", occupancy.skipped_ray_sigmas},
                             {"skipped_rays_near", occupancy.skipped_rays_near},
                             {"object_voxels_skipped", lost},
                             {"seconds", seconds},
                             {"note", occupancy.note}};
    rows.push_back({"air_carving", fields,
                    riner::bench::format("shift %+5.1f px  kept %.4f  fbp %zu  rays near %zu  "
                                         "object skipped %ld  %.2f s",
                                         shift, occupancy.inside_fraction, occupancy.kept_by_fbp,
                                         occupancy.skipped_rays_near, lost, seconds)});
  }
  return rows;
}

}  // namespace

RINER_BENCH_CASE(air_carving, "skipping the air alone: grid kept, checks, object skipped",
                 air_carving);
