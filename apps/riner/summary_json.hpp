// The JSON riner reports, shared by the CLI and the Python module: a device's capabilities and
// training plan, and what summary.json says about a reconstruction (the run: steps, time,
// memory, coverage, air, dead elements; the ring corrections; the no-reference quality report
// against the FBP of the same scan).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "riner/centre.hpp"
#include "riner/device.hpp"
#include "riner/fbp.hpp"
#include "riner/flat_field.hpp"
#include "riner/quality.hpp"
#include "riner/reconstructor.hpp"

namespace riner::app {

// `riner devices --json`: the capabilities riner relies on and the plan it would train with.
nlohmann::json device_json(const DeviceInfo& device);

// What a user without a ground truth can check (riner/quality.hpp): rings, specks and the
// centre against the FBP of the same scan, for the image and (the centre, 2D) the trained field.
struct QualityCheck {
  QualityReport image;
  std::optional<CentreDeviation> field;  // 2D only
  // 3D: the axial slices measured (the FDK is reconstructed on those only) and of how many.
  std::vector<std::size_t> slices;
  std::size_t volume_slices = 0;
};

QualityCheck check_quality(const Reconstructor& r, const ReconstructionResult& result,
                           const std::optional<Device>& device);
// InputError when the grid's slices are too small for check_quality (kQualitySmallestSide):
// called before training, so that a run does not end in that error after it.
void require_quality_grid(const Geometry& g);
// InputError when a whole run's grid and readings could not fit the machine's memory (a grid
// of 30000 x 30000 trained for about 110 s before "out of memory"): said before any work.
void require_memory(const Geometry& g);
// InputError for 0 training steps without a warm start: the image would be the untrained
// field's noise (the library allows it, to look at the initial state).
void require_training(const RinerConfig& c);
// summary.json's "quality".
nlohmann::json quality_summary(const QualityCheck& check);

// Every field of summary.json that the reconstruction itself decides (the caller adds where
// the outputs went, the flat field and the centre).
nlohmann::json run_summary(const Reconstructor& r, const ReconstructionResult& result,
                           const QualityCheck& quality);

// summary.json's account of each dead element: index, reason, beta, invalid readings.
nlohmann::json dead_elements_json(const std::vector<DeadElement>& dead);
// Each element whose response changes or that dies part-way, with its segments of views.
nlohmann::json changing_elements_json(const std::vector<ChangingElement>& changing);
nlohmann::json flat_field_json(const FlatFieldReport& report);
nlohmann::json centre_json(const CentreEstimate& estimate);
// What FBP did (`riner fbp --json`, Python's riner.fbp report): the readings it interpolated, the
// stopped beam's count and floor, a short scan, Parker's weights, a half acquisition's overlap.
nlohmann::json fbp_report_json(const FbpReport& report);

// Further from the scan's own estimate of its axis (`riner center`) than this, the geometry's
// offset is doubted aloud: half a pixel blurs little, a few pixels double edges.
constexpr double kCentreDoubtPx = 1.0;

// The scan's own estimate of its axis, to check the geometry's offset against, and in `note`
// what to say (without a "note: " of its own): that the two differ by more than kCentreDoubtPx, or
// that the search cannot check this geometry (empty when there is nothing to say). nullopt for
// scans without a half-turn or a view pair (a fan or cone beam: a full turn). The CLI prints the
// note, the Python module warns with it.
std::optional<CentreEstimate> check_geometry_centre(const Scan& scan, std::string& note);

}  // namespace riner::app
