// Pieces several subcommands share: device and engine flags, output folders, summaries.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "cli_args.hpp"
#include "riner/array.hpp"
#include "riner/destripe.hpp"
#include "riner/device.hpp"
#include "riner/engine.hpp"
#include "riner/geometry.hpp"
#include "riner/quality.hpp"
#include "riner/scan.hpp"

namespace riner::app {

// --device and --engine (opencl | reference).
void add_engine_flags(Args& args);
Engine engine_from(const Args& args);
// The device for the OpenCL engine (nullopt for the reference engine).
std::optional<Device> device_from(const Args& args, Engine engine);

// Creates the folder (and parents) if needed; InputError if it is a file, an input (a folder of
// TIFFs read as a stack), or a folder this process cannot write into (said now, not after
// training).
std::filesystem::path make_output_dir(const std::string& path);

// InputError "refusing to overwrite an input file" when any of `names` in `out` was read as an
// input: checked once the inputs are read and before anything is trained or written, so a
// refused run leaves the folder as it was (the writers check again as they write).
void refuse_outputs_over_inputs(const std::filesystem::path& out,
                                const std::vector<std::string>& names);

// Removes what an earlier run left of `names` in `out`, called before a run writes its first
// output: a run killed part-way then leaves a set short of files, never one of two runs (a new
// sino.npy beside an earlier run's geometry.json of the same shape was read without a word).
void clear_previous_outputs(const std::filesystem::path& out,
                            const std::vector<std::string>& names);

// `text` in lower case ("AUTO" -> "auto", ".PNG" -> ".png").
std::string lowercase(std::string text);

// "a,b,,c" -> {"a", "b", "", "c"}: the items of an option's comma-separated list.
std::vector<std::string> split_commas(const std::string& list);

// A preset name or a geometry JSON file.
Geometry geometry_from(const std::string& name_or_path);

// Human lines go to stdout, or to stderr when stdout carries --json; nothing with --quiet.
class Console {
 public:
  explicit Console(const Args& args) : json_(args.is_set("json")), quiet_(args.is_set("quiet")) {}
  void line(const std::string& text) const;
  // With --json, prints the summary on stdout.
  void summary(const nlohmann::json& json) const;
  bool quiet() const { return quiet_; }

 private:
  bool json_;
  bool quiet_;
};

nlohmann::json metrics_json(double psnr, double ssim, double mae, double rmse, double data_range);

// Where the quality report (against the FBP of the same scan) has doubts, a console note each:
// the centre, specks, lost object, soft edges.
void print_quality_doubts(Console& console, const QualityReport& q);

// A note when classical stripe removal found over a tenth of the detector as large stripes: the
// detection reading the object's structure (Vo's rule alone on neutron360: 149 of 503 elements,
// 785 pixels of object set to air; docs/guide/destripe.md), with what to try instead.
void note_large_stripes(Console& console, const DestripeReport& report);
// The measurement's NaN/inf readings, counted for a reconstruction (nothing when there are none).
void note_non_finite(const Console& console, std::size_t non_finite);
// The +inf readings training keeps as bounds (TrainingStats::starved_readings).
void note_starved_readings(const Console& console, std::size_t count, float floor);
// The voxels in the full shadow of what stopped the beam (model/stopped_hull.hpp), whose
// contents the readings do not say; `mean` the image's there (a slab run's summary has none).
void note_stopped_hull(const Console& console, std::size_t voxels, std::optional<double> mean);
// The detector rows training filled from the rows beside them (TrainingStats::filled_rows).
void note_filled_rows(const Console& console, const std::vector<std::size_t>& rows);
// Before training: a warning when the views leave lines never measured (views_miss_lines), as
// riner fbp warns (before, reconstruct said nothing of a 0.5-degree arc).
void note_missing_lines(const Console& console, const Geometry& g);
// A grid reaching kGridBeyondRaysNoted times as far from the axis as the rays (grid_beyond_rays):
// a unit's mistake, most likely (an audit's grid 8 times too wide drew no word).
constexpr double kGridBeyondRaysNoted = 3.0;
void note_grid_beyond_rays(const Console& console, const Geometry& g);
// An object wider than the field of view (edge_reading_share above this; the shared scans read
// 0.001-0.053, an audit's truncated scans 0.6-0.9); not for a half acquisition.
constexpr double kEdgeShareNoted = 0.25;
void note_object_beyond_detector(const Console& console, const Scan& scan);
// Before training: a note when the median view's largest reading is beyond any detector's
// -ln(I/I0) (kMostLineIntegral): readings stored scaled (x1000 integers) train with rings left,
// since alpha's offsets would need responses of e^(hundreds) (the audit: 21.8 dB, ring index
// 0.067 against FBP's 0.070).
constexpr double kMostLineIntegral = 30.0;
void note_unphysical_readings(const Console& console, const Scan& scan);

}  // namespace riner::app
