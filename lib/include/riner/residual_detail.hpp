// The detail the trained field leaves in the readings, given back through FBP.
//
// The field is a smooth fit: at scanner size, and on low-noise scans, the readings hold detail
// it has not learnt (edges, fine texture), which FBP of the readings would show but the field
// does not. What the readings say beyond the field and the learnt responses, the residual
// rho + ln(alpha) - A f, carries that detail and the noise. Its FBP is split between the even
// and the odd views: the detail is the same in both halves, the noise is not, so their
// difference measures the noise where it lies. The residual's FBP is added where it stands
// above that noise (a local Wiener gain), and only on scans where the two halves agree on a
// stated share of the residual's energy, and only when the detail of either half fits the
// other half's readings clearly better than the field alone; on a scan whose residual is noise
// (every shared real scan) nothing changes. Each element's mean residual is taken out first: a
// constant offset along a detector column is alpha's, and its FBP would be a ring.
// (docs/history/RESULTS.md, "Issue 29: the detail the field leaves in the readings".)
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "riner/array.hpp"
#include "riner/device.hpp"
#include "riner/engine.hpp"
#include "riner/scan.hpp"

namespace riner {

struct ResidualDetailSettings {
  bool enabled = true;
  // Given back only when the even and odd views' FBPs agree on this share of the residual's
  // energy (1 - |difference|^2 / |residual FBP|^2 over the sampled pixels): the simulated
  // DeepLesion slices 0.38-0.49, the shared real scans -0.05-0.05.
  double min_consistent_share = 0.2;
  int window_px = 3;  // side of the square over which the Wiener gain compares the two
  // The held-out check projects each half's detail at every k-th view of the other half, k as
  // large as leaves this many readings (a 2D slice's half holds fewer: every view).
  int held_out_readings = 1 << 21;
  // The held-out misfit must fall by this share times the squared consistent share (the bar
  // falls where noise fills the residual): DeepLesion 19-34% at bars of 3.6-4.9%, a
  // Shepp-Logan at 256 columns, whose detail is FBP's own edges, 2-7.4% at bars of 7-10%.
  double min_held_out_fall = 0.15;
};

struct ResidualDetail {
  bool applied = false;
  double consistent_share = 0.0;  // as min_consistent_share measures it
  double mean_gain = 0.0;         // the Wiener gain's mean over the sampled pixels
  double rms_added = 0.0;         // of what was added, over the sampled pixels (1/mm)
  // Held out: mean |rho + ln(alpha) - A image - m| over the odd views' readings with the even
  // views' detail and the other way round (averaged), and the same without; m is each
  // element's mean residual over the scan (alpha's leftover offset, which the detail was made
  // without). The detail is added only when it fits readings it was not taken from better by
  // min_fall. Over every view, or every k-th of each half where that leaves two
  // million readings or more (a volume's scan).
  double misfit_before = 0.0;
  double misfit_after = 0.0;
  double min_fall = 0.0;  // the share it had to fall by: min_held_out_fall x consistent_share^2
  std::size_t held_out_views = 0;  // the views the check projected (both halves')
  double seconds = 0.0;  // what the step took
  std::string note;  // why not applied, when it was not
};

struct ResidualDetailResult {
  Array image;
  ResidualDetail report;
};

// `image` (taken, and given back unchanged when no detail is added) plus the residual's detail.
// `field`: the trained field on the grid (its projection is what the readings are compared with);
// `log_alpha`: ln(alpha) per element or per view and element; `dead`:
// elements whose readings are left out; `sampled`: per pixel, 1 where training sampled (empty:
// all), the only pixels that get detail. Every geometry: in 3D the elements are the detector's
// pixels ([n_v, n_u] values of ln(alpha), or [views, n_v, n_u]), the FBP is FDK (cone beam) or
// slice by slice (parallel beam), and the Wiener gain compares the halves over a cube.
ResidualDetailResult return_residual_detail(Array image, const Array& field, const Scan& scan,
                                            const Array& log_alpha,
                                            const std::vector<std::size_t>& dead,
                                            const std::vector<std::uint8_t>& sampled,
                                            const ResidualDetailSettings& settings,
                                            Engine engine = Engine::kOpenCL,
                                            std::optional<Device> device = std::nullopt);

}  // namespace riner
