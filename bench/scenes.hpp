// What the Riner benchmarks reconstruct: the DeepLesion slices simulated by the paper protocol
// (METHOD.md section 4) when ../shared is present, else built-in Shepp-Logan ring scans in the
// same geometry, plus the settings and detector scores every Riner case shares.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "harness.hpp"
#include "riner/io.hpp"
#include "riner/projector.hpp"
#include "riner/riner_config.hpp"
#include "riner/simulate.hpp"

namespace riner::bench {

struct RingScene {
  std::string name;  // "deeplesion/slice_3" or "shepp-logan/seed_3"
  SimulatedScan sim;
};

// --data=DIR (default ../shared/data/deeplesion; "builtin" for the phantoms). Falls back to the
// phantoms, with a note on stderr, only when the default folder is missing.
bool uses_deeplesion(const Options& o);
// Scene `index` (a slice index, also the ring seed) in the fan2d-paper geometry. --seed-offset=N
// adds N to the seed: the same slices with other responses, dead elements and noise (a check
// of settings chosen on the default seeds). `model`: the paper's ring model unless given (its
// seed is replaced as above).
RingScene paper_scene(const Options& o, int index, const Projector& projector,
                      RingModel model = {});

// A synchrotron-like 2D parallel beam: 360 views over 180 degrees, 367 elements of 1 mm (wide
// enough for the 256 x 256 grid's diagonal), the axis offset_px from the detector's centre.
Geometry parallel_half_turn(double offset_px = 0.0);

// The defaults, then --config=FILE|JSON, then --steps, then --engine.
RinerConfig config_from(const Options& o);

// How well alpha and beta match the truth: mean |alpha err| over live elements, dead elements
// flagged among those whose rays cross the object (clean column mean >= 0.1, elsewhere flagging
// is moot), live elements switched off, and each dead element's details. Flagged: beta < 0.5,
// or in `reported_dead` (Reconstructor::dead_elements(): also the elements whose readings are
// invalid, which a volume's few rays per pixel leave at beta 0.8-1; "dead_flagged_by_beta"
// counts beta alone).
nlohmann::json detector_accuracy(const Array& alpha, const Array& beta, const SimulatedScan& sim,
                                 const std::vector<std::size_t>& reported_dead = {});

// Images of one shape side by side in one PNG (a figure: truth | FBP | riner ...).
void write_panel_png(const std::string& path, const std::vector<const Array*>& images,
                     const Window& window);

}  // namespace riner::bench
