// The ring corrections of riner/ring_correction.hpp as a reconstruction runs them: mirror pairs,
// air, radial gradient, detector response, radial gradient again, each that the settings turn
// on, each fed the image and alpha the one before left. Used for a slice (Reconstructor) and for each slice of a
// parallel-beam volume (riner/volume_ring_correction.hpp). A slice whose readings' detail is
// given back gets the radial gradient once more after it (Reconstructor, rings.gradient_after_detail).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "riner/array.hpp"
#include "riner/geometry.hpp"
#include "riner/riner_config.hpp"
#include "riner/ring_correction.hpp"

namespace riner {

struct RingChain {
  Array image;  // after the last correction that ran
  Array alpha;
  std::optional<RingCorrection> air;  // each correction that ran, as it returned
  std::optional<RingCorrection> gradient;
  std::optional<RingCorrection> response;
  std::optional<RingCorrection> gradient_after_response;
  std::optional<RingCorrection> mirror;
};

// 2D geometry; `dead_elements` as correct_rings_from_response takes them. `sampled`: per pixel
// (C order), 0 where training skipped the pixel as air and the image holds 0, or empty (all
// sampled). Each correction subtracts its profile along whole circles; it is taken back out of
// the skipped air before the next correction reads the image, which would otherwise take that
// paint for a ring and move it into the object's outline (the HTC disc: a 0.002/mm halo).
RingChain correct_rings_in_order(const Array& image, const Array& alpha, const Geometry& geometry,
                                 const std::vector<std::size_t>& dead_elements,
                                 const RingCorrectionConfig& config,
                                 const std::vector<std::uint8_t>& sampled = {});

}  // namespace riner
