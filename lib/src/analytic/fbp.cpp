#include "riner/fbp.hpp"

#include "analytic/fbp_setup.hpp"
#include "analytic/stopped_beam_rows.hpp"
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

std::vector<std::size_t> SliceSelection::slices(std::size_t nz) const {
  if (step == 0) throw InputError("a slice selection's step must be at least 1");
  if (first >= nz)
    throw InputError("the slice selection starts past the volume's " + std::to_string(nz) +
                     " slices");
  const std::size_t fit = (nz - 1 - first) / step + 1;
  if (count > fit)
    throw InputError("the slice selection runs past the volume's " + std::to_string(nz) +
                     " slices");
  std::vector<std::size_t> out(count == 0 ? fit : count);
  for (std::size_t s = 0; s < out.size(); ++s) out[s] = first + s * step;
  return out;
}

SliceSelection SliceSelection::spread(std::size_t nz, std::size_t most) {
  if (nz <= most || most == 0) return {};
  const std::size_t step = (nz + most - 1) / most;
  const std::size_t count = (nz - 1) / step + 1;
  return {(nz - 1 - (count - 1) * step) / 2, step, count};
}

bool views_miss_lines(const Geometry& g) { return analytic::views_miss_lines(g); }

Array fbp(const Scan& scan, const FbpOptions& options, FbpReport* report) {
  scan.geometry.validate();
  // All NaN gave an image of zeros, raw intensities an image of thousands, without a word.
  check_scan(scan, "fbp");
  Geometry g = scan.geometry;  // a half acquisition's detector widens below
  Array weighted = scan.measurement;
  FbpReport local;
  // The readings training keeps as bounds, found as it finds them (a pass only where a reading
  // is +inf), at their row's floor or left to the interpolation below.
  if (options.stopped_beam_at_floor || (report != nullptr && options.count_stopped_beam)) {
    const analytic::StoppedBeamRows stopped =
        analytic::stopped_beam_rows(weighted, g, options.stopped_beam_at_floor);
    if (options.count_stopped_beam) local.stopped_beam_readings = stopped.count;
    local.stopped_beam_floor = stopped.largest_floor;
  }
  local.non_finite_replaced = analytic::repair_non_finite(weighted, g.n_u, g.is_3d() ? g.n_v : 1);
  analytic::cosine_weight(weighted, g);
  std::vector<double> view_weights = analytic::view_weights(g, &local.short_scan);
  if (local.short_scan) {
    local.parker_weighted = analytic::parker_weight(weighted, g, view_weights);
  }
  local.half_acquisition_overlap_mm = analytic::extend_half_acquisition(weighted, g);
  const std::vector<double> taps =
      analytic::filter_taps(g.n_u, analytic::filter_spacing(g), options.filter);
  if (report != nullptr) *report = local;

  std::vector<std::size_t> shape = g.volume_shape;
  std::size_t first = 0;
  std::size_t step = 1;
  if (g.is_3d()) {
    const std::vector<std::size_t> slices = options.slices.slices(shape[0]);
    shape[0] = slices.size();
    first = slices.front();
    step = options.slices.step;
  }
  Array volume(shape);
  if (options.engine == Engine::kReference) {
    const std::vector<double> in(weighted.data.begin(), weighted.data.end());
    // Slices only in 3D: a 2D image is one slice (passing its row count gave ny images).
    const std::vector<double> out = ref::fbp_backproject(
        g, ref::fbp_filter(in, g.n_u, taps), view_weights, first, step, g.is_3d() ? shape[0] : 1);
    volume.data.assign(out.begin(), out.end());
    return volume;
  }
  Device device = options.device ? *options.device : Device::open();
  cl::Context& ctx = cl::context_of(device);
  ops::FbpOp op(ctx, g, taps, view_weights);
  cl::Buffer<float> d_filtered(ctx, weighted.size());
  {
    // The weighted readings go once filtered: a CPU's backprojection holds the filtered ones
    // again as pairs, and on a CPU device every buffer is host memory.
    cl::Buffer<float> d_in(ctx, std::span<const float>(weighted.data));
    weighted = Array();
    op.filter(d_in, d_filtered);
  }
  cl::Buffer<float> d_volume(ctx, volume.size());
  op.backproject(d_filtered, d_volume, first, step);
  d_volume.read(std::span<float>(volume.data));
  return volume;
}

}  // namespace riner
