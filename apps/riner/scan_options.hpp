// The options that name a scan, shared by reconstruct and fbp: SCAN and --geometry, and for raw
// projections --flat and --dark.
#pragma once

#include <nlohmann/json.hpp>
#include <optional>

#include "cli_args.hpp"
#include "riner/flat_field.hpp"
#include "riner/scan.hpp"

namespace riner::app {

void add_scan_options(Args& args);

struct LoadedScan {
  Scan scan;
  std::optional<FlatFieldReport> flat_field;  // set when SCAN held raw projections
};

// The measurement SCAN names, or, with --flat, raw projections normalised by their flat and
// dark fields.
LoadedScan scan_from(const Args& args);

// One line for the console: how many frames went into each field, what became invalid.
std::string flat_field_line(const FlatFieldReport& report);
nlohmann::json flat_field_json(const FlatFieldReport& report);

}  // namespace riner::app
