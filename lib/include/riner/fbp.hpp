// Filtered backprojection: FBP for parallel and fan beam (flat detector), FDK for cone beam,
// slice-wise FBP for parallel 3D. The analytic baseline every reconstruction is measured
// against.
#pragma once

#include <cstddef>
#include <optional>
#include <string_view>

#include "riner/array.hpp"
#include "riner/device.hpp"
#include "riner/engine.hpp"
#include "riner/scan.hpp"

namespace riner {

enum class FbpFilter { kRamLak, kSheppLogan, kHann };

// "ram-lak", "shepp-logan", "hann"; InputError otherwise.
FbpFilter parse_fbp_filter(std::string_view name);
const char* fbp_filter_name(FbpFilter filter);

struct FbpOptions {
  FbpFilter filter = FbpFilter::kRamLak;
  Engine engine = Engine::kOpenCL;
  std::optional<Device> device;  // OpenCL engine; default Device::open()
};

struct FbpReport {
  std::size_t non_finite_replaced = 0;  // NaN/inf measurements interpolated from neighbours
  bool short_scan = false;  // views miss part of the circle (half-circle for parallel beams);
                            // no Parker weighting is applied, so expect streaks
};

// The image/volume on the scan geometry's grid, mu in 1/mm. Non-finite measurements are
// replaced by linear interpolation between the nearest finite elements of the same view row.
Array fbp(const Scan& scan, const FbpOptions& options = {}, FbpReport* report = nullptr);

}  // namespace riner
