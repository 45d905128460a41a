// riner center SCAN: the centre-of-rotation offset the scan's own views point to.
#include <cmath>

#include "cli_common.hpp"
#include "commands.hpp"
#include "riner/geometry_doubts.hpp"
#include "scan_options.hpp"
#include "summary_json.hpp"

namespace riner::app {

int run_center(int argc, char** argv, int first) {
  Args args("center",
            "Estimates where the rotation axis projects on the detector (the geometry's "
            "detector.offset_px) from the whole sinogram: the first half-turn and its mirror "
            "image make one unbroken full-turn sinogram only about the axis (Vo et al. 2014); "
            "views half a turn apart, which a parallel beam sees as mirror images, are the "
            "cross-check. Use the result with --offset-px, or pass --offset-px auto to "
            "reconstruct and fbp.");
  add_scan_options(args);
  args.output_flags();
  if (!args.parse(argc, argv, first)) return 0;
  Console console(args);
  const LoadedScan loaded = scan_from(args, console, GeometryDoubts::kLater);
  // A wrong range or rotation sense stops the centre finders (they pair views by the angles);
  // a fan's distances doubted leave its axis standing, read about that axis and said after it.
  const CentreEstimate e = estimate_centre(loaded.scan);
  console.line(centre_line(e) + "; the geometry says " +
               std::to_string(loaded.scan.geometry.offset_u));
  // The fan checks search 2 px about the offset: within a pixel, the load's reading stands.
  std::vector<std::string> doubts = loaded.geometry_doubts;
  if (std::fabs(e.offset_px - loaded.scan.geometry.offset_u) > 1.0) {
    Scan about_axis = loaded.scan;
    about_axis.geometry.offset_u = e.offset_px;
    doubts = geometry_doubts(about_axis);
  }
  for (const std::string& doubt : doubts) console.line("warning: " + doubt);
  nlohmann::json summary = centre_json(e);
  summary["geometry_offset_px"] = loaded.scan.geometry.offset_u;
  summary["geometry_doubts"] = doubts;
  console.summary(summary);
  return 0;
}

}  // namespace riner::app
