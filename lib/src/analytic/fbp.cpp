#include "riner/fbp.hpp"

#include "analytic/fbp_setup.hpp"
#include "cl/context.hpp"
#include "cl/device_access.hpp"
#include "ops/fbp.hpp"
#include "reference/fbp_ref.hpp"
#include "riner/error.hpp"

namespace riner {

FbpFilter parse_fbp_filter(std::string_view name) {
  if (name == "ram-lak" || name == "ramlak") return FbpFilter::kRamLak;
  if (name == "shepp-logan") return FbpFilter::kSheppLogan;
  if (name == "hann") return FbpFilter::kHann;
  throw InputError("filter must be ram-lak, shepp-logan or hann (got \"" + std::string(name) +
                   "\")");
}

const char* fbp_filter_name(FbpFilter filter) {
  switch (filter) {
    case FbpFilter::kRamLak:
      return "ram-lak";
    case FbpFilter::kSheppLogan:
      return "shepp-logan";
    case FbpFilter::kHann:
      return "hann";
  }
  return "unknown";
}

Array fbp(const Scan& scan, const FbpOptions& options, FbpReport* report) {
  const Geometry& g = scan.geometry;
  g.validate();
  g.check_measurement_shape(scan.measurement.shape);
  Array weighted = scan.measurement;
  FbpReport local;
  local.non_finite_replaced = analytic::repair_non_finite(weighted, g.n_u);
  analytic::cosine_weight(weighted, g);
  const std::vector<double> taps =
      analytic::filter_taps(g.n_u, analytic::filter_spacing(g), options.filter);
  const std::vector<double> view_weights = analytic::view_weights(g, &local.short_scan);
  if (report != nullptr) *report = local;

  Array volume(g.volume_shape);
  if (options.engine == Engine::kReference) {
    const std::vector<double> in(weighted.data.begin(), weighted.data.end());
    const std::vector<double> out =
        ref::fbp_backproject(g, ref::fbp_filter(in, g.n_u, taps), view_weights);
    volume.data.assign(out.begin(), out.end());
    return volume;
  }
  Device device = options.device ? *options.device : Device::open();
  cl::Context& ctx = cl::context_of(device);
  ops::FbpOp op(ctx, g, taps, view_weights);
  cl::Buffer<float> d_in(ctx, std::span<const float>(weighted.data));
  cl::Buffer<float> d_filtered(ctx, weighted.size());
  cl::Buffer<float> d_volume(ctx, volume.size());
  op.filter(d_in, d_filtered);
  op.backproject(d_filtered, d_volume);
  d_volume.read(std::span<float>(volume.data));
  return volume;
}

}  // namespace riner
