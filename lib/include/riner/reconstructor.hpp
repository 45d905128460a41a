// Riner: a ring-artifact-free image from a scan, by training an implicit neural representation
// of the image together with each detector element's response alpha and validity mask beta
// (METHOD.md §1-2). The CLI's `riner reconstruct` is a thin client of this class.
//
//   riner::Reconstructor r(scan, config);   // builds kernels, uploads the scan
//   r.run([](const riner::TrainingProgress& p) { ...; return true; });
//   riner::Array image = r.image();        // mu (1/mm) on the geometry's grid
//   riner::Array alpha = r.alpha();        // estimated response per detector element
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "riner/array.hpp"
#include "riner/device.hpp"
#include "riner/execution_plan.hpp"
#include "riner/residual_detail.hpp"
#include "riner/riner_config.hpp"
#include "riner/ring_correction.hpp"
#include "riner/scan.hpp"
#include "riner/volume_ring_correction.hpp"

namespace riner {

struct LossRecord {
  int step = 0;            // 0-based
  double data_loss = 0.0;  // the L1 data term of the step's batch
  double penalty = 0.0;    // lambda * sum(-beta^2) over the batch's elements
  double learning_rate = 0.0;
};

struct TrainingProgress {
  int step = 0;   // steps done
  int total = 0;  // steps planned
  double loss = 0.0;
  double seconds = 0.0;
};

// Return false to stop training early.
using ProgressCallback = std::function<bool(const TrainingProgress&)>;

// Everything one evaluation of the field gives: the field itself, the image and alpha after the
// ring corrections (the field and the trained alpha when they are off or 3D), and each
// correction as it was made (each runs on the image the one before it left).
struct ReconstructionResult {
  Array field_image;
  Array image;
  Array alpha;
  // When some element's response changes part-way (training.partial_responses): each view's
  // response per element, [n_views, n_u] ([n_views, n_v, n_u] in 3D), the corrections' change
  // to alpha included; otherwise empty.
  Array alpha_by_view;
  std::optional<RingCorrection> air_rings;
  std::optional<RingCorrection> gradient_rings;
  std::optional<RingCorrection> response_rings;
  std::optional<RingCorrection> gradient_after_response_rings;
  // 2D: the gradient correction once more after the readings' detail
  // (rings.gradient_after_detail; only when the detail was added).
  std::optional<RingCorrection> gradient_after_detail_rings;
  std::optional<RingCorrection> mirror_rings;
  // 3D: the same corrections slice by slice (parallel beam; a cone beam gets a note).
  std::optional<VolumeRingCorrection> volume_rings;
  // The readings' detail given back after the corrections (riner/residual_detail.hpp).
  ResidualDetail residual_detail;
  // Voxels whose rays read no light in nearly every view (a metal's full shadow), whose values
  // the readings do not hold (model/stopped_hull.hpp), and the image's mean there.
  std::size_t stopped_hull_voxels = 0;
  double stopped_hull_mean = 0.0;
};

// An element taken for dead, and why: its readings are all non-finite, they stay steady while
// its neighbours' vary (training.stuck_elements), or training switched it off (beta below
// Reconstructor::kDeadBelowBeta).
struct DeadElement {
  std::size_t element = 0;  // flat index ([n_u] in 2D, row-major [n_v, n_u] in 3D)
  double beta = 0.0;
  std::size_t invalid_readings = 0;  // non-finite readings, of one per view
  std::string reason;  // "no finite reading", "stuck: steady while its neighbours vary" or
                       // "beta below 0.5"
};

// Part of the views over which an element's response is one alpha and one beta.
struct ResponseSegment {
  std::size_t first_view = 0;
  std::size_t views = 0;
  double alpha = 1.0;  // as trained
  double beta = 1.0;
};

// An element whose response changes part-way through the scan, or that dies part-way
// (training.partial_responses, model/response_changes.hpp), and its segments in view order.
struct ChangingElement {
  std::size_t element = 0;
  bool dies = false;  // the segments are bounded by runs of non-finite readings
  std::vector<ResponseSegment> segments;
};

// How the training's rays covered the detector: an element's (pixel's, in 3D) alpha and beta
// learn only from its own rays, so one with few is estimated from little.
struct RayCoverage {
  std::uint64_t rays = 0;    // drawn so far, in all
  std::uint32_t fewest = 0;  // rays per element: the least, median and most
  std::uint32_t median = 0;
  std::uint32_t most = 0;
  std::size_t elements_under_10 = 0;  // elements with fewer than 10 rays
};

// What the warm start did (training.warm_start; training/warm_start.hpp).
struct WarmStartStats {
  std::string method;               // the stripe filter
  int fit_steps = 0;                // steps fitting the field to the destriped FBP
  std::size_t fit_pixels = 0;       // pixels fitted (those training samples)
  double fit_residual = 0.0;        // mean |field - FBP| over the last fit steps, 1/mm
  double mean_abs_log_alpha = 0.0;  // mean |ln alpha0| the filter read off the scan
  double seconds = 0.0;             // filter, FBP and fit together
};

struct TrainingStats {
  int steps = 0;
  int steps_planned = 0;            // training.steps
  int rays_per_step = 0;            // training.rays_per_step as resolved
  double draws_per_ray_planned = 0.0;  // steps_planned x rays_per_step / the scan's rays
  // steps_planned x rays_per_step x the rays' mean samples inside the grid / the grid's voxels
  double samples_per_voxel_planned = 0.0;
  bool stopped_on_plateau = false;  // training.stop_on_plateau ended the run early
  // The step training went on from (resume_from a checkpoint); 0 for a run in one go. seconds
  // and samples count the steps before it too.
  int resumed_at_step = 0;
  double seconds = 0.0;             // wall time inside step()/run()
  double samples = 0.0;             // field evaluations trained on (forward + backward)
  std::size_t non_finite = 0;       // measurements that were NaN/inf (treated as 0)
  // Of those, the +inf readings taken for a beam the object stopped, trained as at least
  // starved_floor (the rule: model/starved_readings.hpp in the library).
  std::size_t starved_readings = 0;
  float starved_floor = 0.0f;
  // 3D: detector rows that read nothing in any view, trained on the line between the rows
  // beside them in each view (as FBP fills them); their elements are dead.
  std::vector<std::size_t> filled_rows;
  // The field learnt mu times this (a power of two): 1 unless the scan's typical attenuation per
  // mm lies far from what the defaults were chosen on (model/field_scale.hpp).
  double field_per_mu = 1.0;
  double typical_mu = 0.0;  // per mm: the median view's largest reading over the grid's width
  std::size_t parameters = 0;
  std::string engine;
  std::string device;                 // device name, or "CPU reference"
  std::optional<ExecutionPlan> plan;  // how the OpenCL engine shaped the work (none: reference)
  std::optional<WarmStartStats> warm_start;  // training.warm_start, when it ran
  // Skipping the air (training.skip_air): whether the measurements certified any, the share of
  // the grid still sampled and of the samples kept, and why not when they did not.
  bool air_skipped = false;
  double inside_fraction = 1.0;
  double samples_kept_fraction = 1.0;
  double noise = 0.0;  // the readings' noise sigma the carving used
  std::string air_note;
  // How the carving was checked (model/occupancy.hpp): views that certified nothing (dim or
  // noisy), voxels the rays carved but the binned FBP kept (its binning and noise), and the rays
  // that cross the grid but only skipped voxels with the largest mean excess over their offsets
  // among them (rho, and noise sigmas of such a mean), the check's threshold (5 sigma, more
  // where noise alone would cross it once in ten scans), how many read more, and how many of
  // those pass within the margin's width of the region (something skipped beside the object).
  std::size_t air_outlier_views = 0;
  std::size_t air_fbp_bin = 0;
  double air_fbp_noise = 0.0;
  std::size_t air_kept_by_fbp = 0;
  std::size_t skipped_rays = 0;
  double skipped_ray_excess = 0.0;
  double skipped_ray_sigmas = 0.0;
  double skipped_ray_threshold = 0.0;
  std::size_t skipped_rays_above = 0;
  std::size_t skipped_rays_near = 0;
  // alpha's learning rate over the field's as trained (training.alpha_lr_scale and the
  // measurement's stripe evidence, training.alpha_stripe_scale) and that evidence.
  double alpha_rate = 1.0;
  double stripe_rms = 0.0;
  // What alpha was made of (training.alpha_model, never auto here) and, in 3D, the share of the
  // stripe pattern row x column factors explain (model/factor_evidence.hpp; -1 in 2D).
  AlphaModel alpha_model = AlphaModel::kPerElement;
  double alpha_factor_explained = -1.0;
  // Coarse to fine as trained (training.level_warmup_steps) and the noise evidence that set it
  // when -1: the readings' noise sigma over their 99th percentile.
  int level_warmup_steps = 0;
  double relative_noise = 0.0;
  // Tail averaging as trained (training.tail_average_steps, the same evidence when -1) and the
  // snapshots the result is the mean of so far (0: the last step's parameters, also once
  // training has gone past the planned steps).
  int tail_average_steps = 0;
  int tail_average_snapshots = 0;
  // The rate's decay as trained (training.lr_decay_smooth, in steps where the scan's rays each
  // cross more than training.smooth_decay_max_voxels_per_ray sampled voxels) and that count.
  bool lr_decay_smooth = true;
  double voxels_per_ray = 0.0;
  // Memory, so far: the process's peak resident set (host) and the most bytes of device
  // buffers it held at once (0 on the reference engine).
  std::size_t peak_host_bytes = 0;
  std::size_t peak_device_bytes = 0;
  RayCoverage coverage;
};

class Reconstructor {
 public:
  // The OpenCL engine runs on `device` (default Device::open()). Throws InputError for a scan
  // or configuration that cannot work (see RinerConfig::validate, check_scan).
  Reconstructor(Scan scan, RinerConfig config, std::optional<Device> device = std::nullopt);
  ~Reconstructor();
  Reconstructor(Reconstructor&&) noexcept;
  Reconstructor& operator=(Reconstructor&&) noexcept;

  // n more training steps.
  void step(int n = 1);
  // Trains until config.training.steps (or a loss plateau, training.stop_on_plateau), calling
  // back every `report_every` steps and at the end.
  void run(const ProgressCallback& callback = {}, int report_every = 50);

  int steps_done() const;

  // Training so far (the parameters, Adam's moments, the steps' records), written atomically
  // to `path` between steps: a run killed later goes on from it with resume_from, to the same
  // bits on the same device.
  void save_checkpoint(const std::filesystem::path& path);
  // Goes on from a checkpoint of this scan, these settings and this device, as after the steps
  // it holds. InputError when the file is not a checkpoint or is truncated, or when it is of
  // another scan, other settings or another device (the message says which).
  void resume_from(const std::filesystem::path& path);
  // The result: mu in 1/mm on the geometry's grid and the response per element ([n_u] in 2D,
  // [n_v, n_u] in 3D). In 2D, after the ring corrections config.rings turns on, which change
  // the image and alpha together and keep the data fit.
  Array image() const;
  // An element whose response changes part-way: the geometric mean of its live segments'
  // (beta >= kDeadBelowBeta) by their views; alpha_by_view() has each view's. alpha() and beta()
  // are as riner hands them out (alpha.npy, beta.npy): a dead element (dead_elements()) has
  // alpha 0 and beta 0 (mark_dead_elements), so that beta < kDeadBelowBeta marks every dead
  // element; trained_alpha() and trained_beta() are training's own values.
  Array alpha() const;
  Array beta() const;
  // sigmoid(beta0) per element (its largest segment's where it changes). An element with no
  // finite reading gets no gradient: its beta stays near 1.
  Array trained_beta() const;
  // ReconstructionResult::alpha_by_view, and the elements it is about.
  Array alpha_by_view() const;
  std::vector<ChangingElement> changing_elements() const;
  static constexpr float kDeadBelowBeta = 0.5f;
  // The dead elements: beta < kDeadBelowBeta, or no finite reading at all (where the rays miss
  // the object, training has no reason to switch such an element off), with the reason.
  std::vector<DeadElement> dead_element_report() const;
  // Their flat indices.
  std::vector<std::size_t> dead_elements() const;
  // What training alone gives: the field at every voxel centre (0 where the measurements show
  // air, training.skip_air) and max(alpha0, 1e-8).
  Array field_image() const;
  Array trained_alpha() const;
  // All of the above from one evaluation of the field (kept until the next training step, so
  // image() and alpha() after result() cost nothing more).
  ReconstructionResult result() const;
  std::vector<LossRecord> history() const;
  TrainingStats stats() const;
  const RinerConfig& config() const;
  const Scan& scan() const;

 private:
  ReconstructionResult evaluate_result() const;
  void evaluate_rings(ReconstructionResult& r) const;
  void evaluate_rings_after_detail(ReconstructionResult& r) const;
  void evaluate_residual_detail(ReconstructionResult& r, const std::vector<float>& parameters,
                                const Array& trained_alpha) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A run's checkpoints (Reconstructor::save_checkpoint) as the CLI, the slabs and Python take
// them: call after_report() from run()'s callback; it saves every `seconds` of training and
// where training stops early, and never when `seconds` is 0. discard() removes the file once
// the run's outputs stand for it.
class CheckpointSaver {
 public:
  CheckpointSaver(Reconstructor& reconstructor, std::filesystem::path path, double seconds);
  // `stopping`: training ends at this report (a signal, the caller's choice).
  void after_report(const TrainingProgress& progress, bool stopping);
  void discard() const;

 private:
  Reconstructor& reconstructor_;
  std::filesystem::path path_;
  double seconds_;
  double saved_at_;  // training seconds at the last save (or at the start)
};

// alpha and beta as riner hands them out (alpha.npy, beta.npy, Python): an element taken for
// dead (Reconstructor::dead_elements) has alpha 0, simulate's mark of a dead element, and beta
// 0 where training left it at kDeadBelowBeta or above (an element with no finite reading gets
// no gradient, so its beta stays near 1), so that beta below 0.5 means dead in every case.
void mark_dead_elements(const std::vector<std::size_t>& dead, Array& alpha, Array& beta);

}  // namespace riner
