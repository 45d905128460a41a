// Warm start (training.warm_start, issue 31): training begins where a classical answer ends.
// A stripe filter of riner/destripe.hpp reads each detector element's offset off the scan
// (alpha0 = exp(-removed)), and the field is fitted, pixel by pixel, to the FBP of the
// destriped scan for training.warm_start_steps steps (the field's own kernels, each "ray" one
// sample at a pixel centre reading that pixel's value). The ray-domain training that follows
// then corrects what the filter got wrong instead of starting from a random field and alpha = 1.
#pragma once

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "riner/device.hpp"
#include "riner/reconstructor.hpp"
#include "training/trainer.hpp"

namespace riner::detail {

using TrainerFactory = std::function<std::unique_ptr<Trainer>(const TrainingSetup&)>;

struct WarmStart {
  std::vector<float> parameters;  // the whole initial parameter vector of setup.layout
  WarmStartStats stats;
};

// Whether training.warm_start applies to a scan of geometry g: asked for, and 2D. Both the
// warm schedule (TrainingSetup's steps and rate) and the start itself follow it.
bool warm_start_applies(const TrainingConfig& training, const Geometry& g);

// warm_start_applies for the setup; a volume that asks for one is warned that it starts cold.
bool wants_warm_start(const TrainingSetup& setup);

// make_trainer builds the engine's trainer for the image fit's setup; device: where the filter's
// sorting step and the FBP run (the OpenCL engine).
WarmStart warm_start(const TrainingSetup& setup, const TrainerFactory& make_trainer,
                     std::optional<Device> device);

}  // namespace riner::detail
