// The engine behind a Reconstructor: one training step, the parameters, the field on the grid.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "model/adam_settings.hpp"
#include "model/batch_sampler.hpp"
#include "model/broad_even_hold.hpp"
#include "model/factor_evidence.hpp"
#include "model/noise_evidence.hpp"
#include "model/occupancy.hpp"
#include "model/parameter_layout.hpp"
#include "model/ray_segments.hpp"
#include "model/response_map.hpp"
#include "model/starved_readings.hpp"
#include "model/tail_average.hpp"
#include "riner/device.hpp"
#include "riner/execution_plan.hpp"
#include "riner/reconstructor.hpp"
#include "training/checkpoint_bytes.hpp"

namespace riner::detail {

// What both engines share: layout, rays, batches, schedule.
struct TrainingSetup {
  Scan scan;
  RinerConfig config;
  model::ParameterLayout layout;
  // The rays as trained: their lengths in the field's unit (model/field_scale.hpp), so that a
  // ray's sum of the field's values times dx is its reading.
  model::RaySegments segments;
  // The field learns mu times this (model::field_per_mu; 1 for most scans); field images are
  // divided by it.
  double field_per_mu = 1.0;
  double typical_mu = 0.0;  // model::typical_mu, what field_per_mu was chosen from
  // The +inf readings kept as bounds (a beam the object stopped; model/starved_readings.hpp) and
  // their floor; the other +inf readings were set to NaN.
  model::StarvedReadings starved;
  std::size_t elements_per_view = 0;
  std::uint32_t seed = 0;
  std::vector<std::uint32_t> invalid_readings;  // per response slot: its unread measurements
  // The response slots that read nothing (no finite reading, no bound: a dead element, a stuck
  // one, a changing element's views after it died): they start at training.unread_beta0.
  std::vector<std::size_t> unread_slots;
  // Which alpha0/beta0 each reading uses: one per element, or per segment of views for the
  // elements whose response changes part-way (training.partial_responses).
  model::ResponseMap responses;
  std::vector<model::ResponseChange> response_changes;
  model::Occupancy occupancy;                   // where the object can be (all, without skip_air)
  double samples_in_grid = 0.0;                 // samples of every ray inside the grid
  // What one drawn ray adds to each voxel of the grid on average: samples_in_grid / rays /
  // voxels (x rays per step x steps: the samples per voxel of a run).
  double voxel_samples_per_ray = 0.0;
  // A volume that TrainingConfig::kSteps3d steps would sample fewer than
  // training.min_samples_per_voxel times a voxel: more steps, the volume's table.
  bool short_of_samples = false;
  double samples_kept = 0.0;                    // of those, inside the occupied region
  // The sampled voxels per ray that crosses them; over training.smooth_decay_max_voxels_per_ray
  // the rate decays in steps (config.training.lr_decay_smooth resolved to false).
  double voxels_per_ray = 0.0;
  double stripe_rms = 0.0;                      // model/stripe_evidence.hpp
  double alpha_rate = 1.0;                      // alpha_lr_scale times the stripe evidence's factor
  model::NoiseEvidence noise;       // model/noise_evidence.hpp; sets level_warmup_steps -1
  model::TailAverage tail_average;  // which steps' parameters the result averages
  // Detector rows with no finite reading, filled from the rows beside them (model/dead_rows.hpp).
  std::vector<std::size_t> filled_rows;
  std::vector<std::uint8_t> stuck;  // per element, model/stuck_elements.hpp (readings now NaN)
  std::size_t stuck_count = 0;
  model::FactorEvidence factor_evidence;             // 3D, model/factor_evidence.hpp
  AlphaModel alpha_model = AlphaModel::kPerElement;  // as trained (never auto)
  // The parameters training starts from (training/warm_start.hpp); empty: the layout's random
  // initial values (model::initial_parameters).
  std::vector<float> initial;

  // device: where the air carving's FBP check runs (the OpenCL engine; default Device::open()).
  TrainingSetup(Scan scan, RinerConfig config, std::optional<Device> device = std::nullopt);
  TrainingSetup() = default;  // filled by hand (the warm start's image fit)
  // What both engines start from: `initial`, or the layout's random initial values.
  std::vector<float> initial_parameters() const;
  double learning_rate(int step) const;
  // Adam settings of a step, for both engines: the schedule for the field, alpha0 and beta0,
  // and the lazy range (training.sparse_adam).
  model::AdamSettings adam_settings(int step) const;
  // Whether all of alpha is held at this step (training.alpha_warmup_steps), or only its broad
  // even part (training.alpha_warmup_broad_px on a 2D full turn; the engines apply
  // `broad_even_hold` after Adam).
  bool holds_all_alpha(int step) const;
  bool holds_broad_even_alpha(int step) const;
  // The hold of alpha's broad even part from the engine's initial alpha0 (one per element);
  // nullopt when the run holds none.
  std::optional<model::BroadEvenHold> broad_even_hold(std::span<const float> initial_alpha) const;
  // Whether beta0 of the elements without invalid readings is held at this step (warm-up).
  bool hold_valid_beta(int step) const { return step < config.training.beta_warmup(); }
  // Scale of each encoding level's features at a step (coarse to fine); all 1 when done.
  std::vector<float> level_weights(int step) const;
};

class Trainer {
 public:
  virtual ~Trainer() = default;
  // One step (0-based index).
  virtual void step(int index, const model::Batch& batch) = 0;
  // Loss records of the steps since the last call, in order.
  virtual std::vector<LossRecord> drain_losses() = 0;
  virtual std::vector<float> parameters() = 0;
  virtual std::vector<float> evaluate_grid() = 0;
  virtual std::string device_name() const = 0;
  // The execution plan the engine runs (none for the reference engine).
  virtual std::optional<ExecutionPlan> plan() const = 0;
  // Everything the later steps depend on beyond the setup (the parameters, Adam's moments, the
  // tail average's sum), for a checkpoint; call after drain_losses(). restore_state takes it
  // back into a trainer made from the same setup, as after `steps` steps.
  virtual void save_state(ByteWriter& out) = 0;
  virtual void restore_state(ByteReader& in, int steps) = 0;
};

std::unique_ptr<Trainer> make_reference_trainer(const TrainingSetup& setup);
std::unique_ptr<Trainer> make_opencl_trainer(const TrainingSetup& setup, Device device,
                                             const ExecutionPlan& plan);

}  // namespace riner::detail
