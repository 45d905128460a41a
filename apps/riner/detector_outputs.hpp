// Writing what a reconstruction learnt about the detector: alpha and beta arrays and a plot
// (2D) or maps (3D).
#pragma once

#include <filesystem>
#include <vector>

#include "riner/array.hpp"
#include "riner/reconstructor.hpp"

namespace riner::app {

// alpha.npy, beta.npy and detector.png in dir: alpha and beta against element index with the
// elements taken for dead marked (`dead`, flat indices); in 3D, the alpha map beside the beta
// map with the dead pixels at 0. alpha_by_view, when not empty (responses that change part-way,
// ReconstructionResult::alpha_by_view): alpha_by_view.npy beside them. The dead are marked in
// alpha and beta too (mark_dead_elements).
void write_detector_outputs(const std::filesystem::path& dir, Array alpha, Array beta,
                            const std::vector<std::size_t>& dead,
                            const Array& alpha_by_view = Array());

}  // namespace riner::app
