// The options that name a scan, shared by reconstruct and fbp: SCAN and --geometry, and for raw
// projections --flat and --dark.
#pragma once

#include <optional>

#include "cli_args.hpp"
#include "cli_common.hpp"
#include "riner/centre.hpp"
#include "riner/flat_field.hpp"
#include "riner/scan.hpp"

namespace riner::app {

void add_scan_options(Args& args);

struct LoadedScan {
  Scan scan;
  std::optional<FlatFieldReport> flat_field;  // set when SCAN held raw projections
  std::optional<CentreEstimate> centre;       // set by --offset-px auto
};

// The measurement SCAN names, or, with --flat, raw projections normalised by their flat and
// dark fields; its detector offset from --offset-px (a number, or auto: estimated).
// Console lines say what was done.
LoadedScan scan_from(const Args& args, const Console& console);

// One line for the console: how many frames went into each field, what became invalid.
std::string flat_field_line(const FlatFieldReport& report);

std::string centre_line(const CentreEstimate& estimate);

}  // namespace riner::app
