// The options that name a scan, shared by reconstruct and fbp: SCAN and --geometry, and for raw
// projections --flat and --dark.
#pragma once

#include <optional>

#include "cli_args.hpp"
#include "cli_common.hpp"
#include "scan_source.hpp"

namespace riner::app {

void add_scan_options(Args& args);

// The measurement SCAN names, or, with --flat, raw projections normalised by their flat and
// dark fields; its detector offset from --offset-px (a number, or auto: estimated).
// Console lines say what was done.
LoadedScan scan_from(const Args& args, const Console& console);

}  // namespace riner::app
