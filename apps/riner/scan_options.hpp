// The options that name a scan, shared by reconstruct and fbp: SCAN and --geometry, and for raw
// projections --flat and --dark.
#pragma once

#include <optional>

#include "cli_args.hpp"
#include "cli_common.hpp"
#include "riner/scan_source.hpp"

namespace riner::app {

void add_scan_options(Args& args);

// The scan as the options name it (UsageError for a combination that cannot work).
ScanSource source_from(const Args& args);
// What the command read, for summary.json: the scan, geometry, flat, dark and flats after it as
// given (null where not), the row and the centre offset asked for.
nlohmann::json inputs_json(const Args& args);

// The geometry of the projection stack the options name, from the files' headers alone (no
// data, no centre estimate): what deciding on slabs needs. nullopt for one detector row
// (--row), a 2D scan, or a scan the whole-scan path explains better (its InputError).
std::optional<Geometry> stack_geometry(const Args& args);

// The measurement SCAN names, or, with --flat, raw projections normalised by their flat and
// dark fields; its detector offset from --offset-px (a number, or auto: estimated).
// Console lines say what was done, and (kWarn) warn of what the readings say against the
// geometry (riner/geometry_doubts.hpp); kLater leaves that to the command.
enum class GeometryDoubts { kWarn, kLater };
LoadedScan scan_from(const Args& args, const Console& console,
                     GeometryDoubts doubts = GeometryDoubts::kWarn);

// A scan whose offset was given (not auto): check_geometry_centre (summary_json.hpp), its note
// on the console. nullopt for auto offsets.
std::optional<CentreEstimate> check_centre(const LoadedScan& loaded, const Console& console);

}  // namespace riner::app
