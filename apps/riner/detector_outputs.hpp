// Writing what a reconstruction learnt about the detector: alpha and beta arrays and a plot
// (2D) or maps (3D).
#pragma once

#include <filesystem>
#include <vector>

#include "riner/array.hpp"

namespace riner::app {

// alpha.npy, beta.npy and detector.png (both against element index; in 3D, alpha and beta maps
// side by side) in dir.
void write_detector_outputs(const std::filesystem::path& dir, const Array& alpha,
                            const Array& beta);

}  // namespace riner::app
