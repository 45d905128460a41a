// Ring-artifact simulation (METHOD.md §4): per-element detector responses alpha (some
// elements non-ideal, some dead), Poisson photon counts, rho = -ln(I / I0). Reproducible from a
// seed: the random draws come from one std::mt19937_64 stream with riner's own samplers, so the
// same seed gives bit-identical output on any platform (given the same clean projections).
#pragma once

#include <cstdint>
#include <string_view>

#include "riner/array.hpp"
#include "riner/geometry.hpp"
#include "riner/projector.hpp"
#include "riner/scan.hpp"

namespace riner {

// How the non-ideal responses are laid out. Per element: each pixel its own (the paper's).
// Rows x columns (3D): alpha(r, c) = a_r b_c, with round(nonideal_fraction * rows) row factors
// and as many column factors ~ U[sqrt(alpha_min), sqrt(alpha_max)] (the rest 1): the gains of
// a detector read out by line or by column amplifier.
enum class ResponsePattern { kPerElement, kRowsTimesColumns };

struct RingModel {
  ResponsePattern pattern = ResponsePattern::kPerElement;
  double nonideal_fraction = 0.75;  // of all detector elements (pixels in 3D), exactly rounded
  double alpha_min = 0.75;          // non-ideal responses ~ U[alpha_min, alpha_max]
  double alpha_max = 1.25;
  std::size_t dead_elements = 2;  // alpha = 0: the whole column reads +inf
  std::size_t dead_rows = 0;      // 3D: whole detector rows dead
  std::size_t dead_columns = 0;   // 3D: whole detector columns dead
  // Partial rings: elements (pixels) whose response changes part-way through the scan, from a
  // view drawn in the middle three fifths on, to a new value ~ U[alpha_min, alpha_max] at least
  // 15% (in log) from the old; and elements that die part-way (alpha 0 from such a view on).
  // With either, the responses are per view: [n_views, n_u] ([n_views, n_v, n_u] in 3D).
  std::size_t partial_elements = 0;
  std::size_t partial_dead_elements = 0;
  double photons = 1e7;           // I0; 0 = no noise (rho = p - ln alpha exactly)
  std::uint64_t seed = 0;

  void validate() const;  // InputError for impossible settings
};

// True responses: alpha per element, [n_u] in 2D and [n_v, n_u] in 3D; 0 marks dead elements.
// Exactly round(nonideal_fraction * n) elements get U[alpha_min, alpha_max]; exactly
// dead_elements (plus whole rows/columns) get 0; the rest get 1. Dead elements are chosen
// first, then the non-ideal ones among the others. With partial elements, the responses per
// view ([n_views, n_u], [n_views, n_v, n_u]): partial_elements live elements, then
// partial_dead_elements others, change from a drawn view on.
Array draw_responses(const Geometry& g, const RingModel& model);

// rho~ from clean line integrals: I ~ Poisson(alpha I0 exp(-p)), rho~ = -ln(I / I0); I = 0
// (every dead element, or a starved ray) gives +inf. alpha: per element (one view's size) or
// per view and element (the measurement's size). Consumes the stream after draw_responses.
Array corrupt_measurement(const Array& clean, const Array& alpha, const RingModel& model);

// The elements of responses `alpha` (per element, or [n_views, elements]) that read 0 in every
// view (dead), and those that read 0 in some views only (dead part-way).
std::vector<std::size_t> dead_in_every_view(const Array& alpha, std::size_t elements);
std::vector<std::size_t> dead_part_way(const Array& alpha, std::size_t elements);
// The views where element e's response in `alpha` (per view: n_views x the detector's elements)
// differs from the view before; none for responses per element.
std::vector<std::size_t> response_change_views(const Array& alpha, const Geometry& g,
                                               std::size_t e);

struct SimulatedScan {
  Scan scan;           // the ring-corrupted, noisy measurement and its geometry
  Array clean;         // exact projections of the ground truth: no rings, no noise
  Array alpha;         // true responses (0 = dead)
  Array ground_truth;  // mu (1/mm) on the geometry's grid
};

// Projects the ground truth with `projector` and corrupts it.
SimulatedScan simulate(const Array& ground_truth, const Projector& projector,
                       const RingModel& model);

// Named geometries of METHOD.md §4: "fan2d-paper" (the DeepLesion/LIDC setting) and
// "cone3d-paper" (the AAPM setting), and "parallel3d" (that volume in a parallel beam over
// 180 degrees); InputError for other names.
Geometry preset_geometry(std::string_view name);
bool is_preset_geometry(std::string_view name);

}  // namespace riner
