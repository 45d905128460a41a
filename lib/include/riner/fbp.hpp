// Filtered backprojection: FBP for parallel and fan beam (flat detector), FDK for cone beam,
// slice-wise FBP for parallel 3D. The analytic baseline every reconstruction is measured
// against.
#pragma once

#include <cstddef>
#include <optional>
#include <string_view>
#include <vector>

#include "riner/array.hpp"
#include "riner/device.hpp"
#include "riner/engine.hpp"
#include "riner/scan.hpp"

namespace riner {

enum class FbpFilter { kRamLak, kSheppLogan, kHann };

// "ram-lak", "shepp-logan", "hann"; InputError otherwise.
FbpFilter parse_fbp_filter(std::string_view name);
const char* fbp_filter_name(FbpFilter filter);

// Axial slices first, first + step, ... of a volume, count of them (0: all that fit).
struct SliceSelection {
  std::size_t first = 0;
  std::size_t step = 1;
  std::size_t count = 0;
  // The selection's slices of a volume of nz; InputError when it names none or one past nz.
  std::vector<std::size_t> slices(std::size_t nz) const;
  // Up to `most` slices spread evenly over nz, centred.
  static SliceSelection spread(std::size_t nz, std::size_t most);
};

struct FbpOptions {
  FbpFilter filter = FbpFilter::kRamLak;
  // 3D: reconstruct only these axial slices (the result is [selected, ny, nx]); the
  // backprojection's time and memory scale with them. Each slice's values are those of the
  // whole volume's.
  SliceSelection slices;
  Engine engine = Engine::kOpenCL;
  std::optional<Device> device;  // OpenCL engine; default Device::open()
  // With a report: count FbpReport::stopped_beam_readings (a pass over the readings where any
  // is +inf; a slab run counts each row once itself).
  bool count_stopped_beam = true;
  // Readings of +inf where the object stopped the beam (model/starved_readings.hpp: metal) read,
  // beside a metal's edge or on the axis, as their detector row's floor (the largest finite
  // reading of nine views in ten; a 2D scan's: the bound training keeps): the metal shows,
  // lighter than it is, with its streaks. false: interpolated from their neighbours like every
  // other invalid reading, so the image shows no metal there (a reference that must not streak,
  // and whose edges are the object's: the quality report's).
  bool stopped_beam_at_floor = true;
};

struct FbpReport {
  std::size_t non_finite_replaced = 0;  // NaN/inf measurements interpolated from neighbours
  // Readings of +inf where the object stopped the beam (metal: training keeps them as bounds,
  // model/starved_readings.hpp), and the largest reading they took (their rows' floors,
  // FbpOptions::stopped_beam_at_floor; 0 when interpolated with the non-finite ones).
  std::size_t stopped_beam_readings = 0;
  float stopped_beam_floor = 0.0f;
  bool short_scan = false;  // views miss part of the circle (half-circle for parallel beams)
  // A fan or cone beam's short scan (half a turn plus the fan, or more) weighted by Parker's
  // weights, each line counted once; a short scan without it misses lines: expect streaks.
  bool parker_weighted = false;
  // A full turn with the axis near one end of the detector (half acquisition): the overlap
  // around the axis, +- this many mm, blended between conjugate rays; 0 for a centred detector.
  double half_acquisition_overlap_mm = 0.0;
};

// The image/volume on the scan geometry's grid, mu in 1/mm. Non-finite measurements are
// replaced by linear interpolation between the nearest finite elements of the same view row;
// a row with none (a dead detector row) from the rows beside it, a view with none from the
// views beside it.
Array fbp(const Scan& scan, const FbpOptions& options = {}, FbpReport* report = nullptr);

// Whether the views leave lines never measured: part of the circle unseen (a parallel beam's
// half turn; a fan or cone beam's half turn plus the fan) and no short scan Parker's weights
// complete. FBP streaks there, and riner's field there rests on no reading.
bool views_miss_lines(const Geometry& g);

}  // namespace riner
