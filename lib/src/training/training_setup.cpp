#include <algorithm>
#include <cmath>

#include "model/dead_rows.hpp"
#include "model/factor_evidence.hpp"
#include "model/field_scale.hpp"
#include "model/response_changes.hpp"
#include "model/starved_readings.hpp"
#include "model/stripe_evidence.hpp"
#include "model/stuck_elements.hpp"
#include "riner/error.hpp"
#include "riner/execution_plan.hpp"
#include "riner/geometry.hpp"
#include "training/trainer.hpp"
#include "training/warm_start.hpp"

namespace riner::detail {

namespace {

// Whether the views read every line through the field twice, once from each side of the axis
// (a full turn, not a half acquisition): the part of an element's offset that its mirror
// element lacks then shows as a misfit between the two readings of each line, so alpha's
// narrow part can learn before the field has drawn the object. A 180-degree scan reads each
// line once: any offset reads like object there, and alpha learning early takes the object's
// edges (the 1100-column faint square: all of alpha held 35.40 dB and no object lost, its broad
// even part only 33.95 and 12 pixels lost; over 360 degrees 34.24 and 34.93). A dense 180-degree
// Shepp-Logan keeps 0.30 dB less this way (docs/history/RESULTS.md, issue 29).
bool reads_lines_twice(const Geometry& g) { return covers_full_turn(g) && !is_half_acquisition(g); }

// A step's rays as the step rules count them: at most the CPU plan's 160 (the plan's when 0).
double capped_batch(const TrainingConfig& t) {
  const int cap = ExecutionPlan::kCpuRaysPerStep;
  return static_cast<double>(t.rays_per_step > 0 ? std::min(t.rays_per_step, cap) : cap);
}

// The steps when the config leaves them to the scan (-1): the dimension's default, and for a
// slice raised so that each of its rays is drawn training.min_draws_per_ray times over the run.
// Scans larger than the paper's draw each ray fewer times at a fixed budget (24 000 steps of
// 160 rays: a 1024-column ray 5 times, a 2048-column one 1.3) and their images blur; more
// steps buy more than a bigger batch at the same draws (docs/history/RESULTS.md, issue 29). A
// volume short of samples (short_of_samples) gets steps until its voxels are sampled
// training.min_samples_per_voxel times each: its rays are drawn well under once however long
// it trains, and what its field lacks is samples per unknown (issue 34).
// Both count batches of at most the CPU plan's 160 rays: a GPU's 640 keeps the CPU's steps and
// draws each ray four times as often, because at 2048 columns the steps were what counted (10
// draws of 640 rays: 3.4 dB under the oracle FBP; 40 draws, the same steps as the CPU's: 1.8 dB
// over it; docs/history/RESULTS.md, issue 29). Needs rays_per_step resolved (the
// Reconstructor's execution plan); left at 0, the default stays.
void resolve_steps(TrainingConfig& t, const Geometry& g, double samples_per_voxel_step,
                   bool volume) {
  const bool left_to_scan = t.steps == TrainingConfig::kScanSteps;
  t.steps = t.steps_for(g.is_3d());
  const bool grows =
      left_to_scan && t.rays_per_step > 0 && t.sampler != Sampler::kViewsTimesElements;
  double wanted = 0.0;
  if (grows && !g.is_3d() && t.min_draws_per_ray > 0.0) {
    const double rays = static_cast<double>(g.n_views()) * static_cast<double>(g.n_u);
    wanted = std::ceil(t.min_draws_per_ray * rays / capped_batch(t));
  }
  if (grows && volume) wanted = std::ceil(t.min_samples_per_voxel / samples_per_voxel_step);
  if (wanted > t.steps) t.steps = static_cast<int>(std::min<double>(wanted, 1 << 30));
  // A warm start's schedule (TrainingConfig::warm_start_lr_scale).
  if (warm_start_applies(t, g)) {
    if (left_to_scan) t.steps = (t.steps + 2) / 3;
    t.learning_rate *= t.warm_start_lr_scale;
  }
}

// How many unknowns each reading has to pin down: the voxels training samples (the region left
// by the air carving) over the rays that cross them (segments as clipped to it).
double sampled_voxels_per_ray(const model::Occupancy& occupancy,
                              const model::RaySegments& segments) {
  const double voxels = occupancy.inside_fraction * static_cast<double>(occupancy.inside.size());
  std::size_t rays = 0;
  for (std::size_t r = 0; r < segments.size(); ++r) rays += segments.count(r) > 0;
  return rays > 0 ? voxels / static_cast<double>(rays) : 0.0;
}

// TrainingConfig::kScanAlphaWarmup's rule.
void resolve_alpha_warmup(TrainingConfig& t, const Geometry& g) {
  if (t.alpha_warmup_steps != TrainingConfig::kScanAlphaWarmup) return;
  const bool wide = !g.is_3d() && g.n_u >= TrainingConfig::kWideDetectorElements;
  t.alpha_warmup_steps = wide && !warm_start_applies(t, g) ? TrainingConfig::kWideAlphaWarmup : 0;
}

}  // namespace

TrainingSetup::TrainingSetup(Scan s, RinerConfig c, std::optional<Device> device)
    : scan(std::move(s)), config(std::move(c)) {
  config.validate();
  scan.geometry.validate();
  // Ray ids, samples' voxels and the field's evaluation are 32-bit in the kernels.
  check_piece_size(scan.geometry, "training");
  check_scan(scan);
  // A reading beyond any line integral is a corrupt value: dead for training as a non-finite
  // one is (FBP repairs both alike), not a target a field and alpha chase.
  scan.non_finite += mark_corrupt_readings(scan.measurement, scan.geometry.n_views());
  // A beam the object stopped (+inf beside rays near the largest reading) is a bound, not a
  // dead element's 0: metal read as air where it was taken as one.
  starved = model::mark_starved_readings(scan.measurement, scan.geometry.n_views(),
                                         model::axis_column(scan.geometry), &scan.geometry);
  filled_rows = model::fill_dead_rows(scan.measurement, scan.geometry);
  const Geometry& g = scan.geometry;
  elements_per_view = g.n_u * (g.is_3d() ? g.n_v : 1);
  typical_mu = model::typical_mu(scan.measurement, g);
  field_per_mu = model::field_per_mu(typical_mu);
  const Geometry field_units = model::lengths_divided(g, field_per_mu);
  segments = model::RaySegments(field_units, config.training.sample_spacing * field_units.voxel_mm,
                                config.training.circle_region);
  std::size_t hit = 0;
  for (std::size_t r = 0; r < segments.size(); ++r) {
    hit += segments.count(r) > 0;
    samples_in_grid += segments.count(r);
  }
  if (hit == 0)
    throw InputError("no detector ray crosses the reconstruction grid: check the geometry");
  samples_kept = samples_in_grid;
  voxel_samples_per_ray = samples_in_grid / static_cast<double>(segments.size()) /
                          static_cast<double>(shape_size(g.volume_shape));
  // The voxels' mean samples per step of the capped batch; short of samples at the 3D floor?
  const double per_voxel_step = capped_batch(config.training) * voxel_samples_per_ray;
  short_of_samples = g.is_3d() && config.training.min_samples_per_voxel > 0.0 &&
                     TrainingConfig::kSteps3d * per_voxel_step < config.training.min_samples_per_voxel;
  resolve_steps(config.training, g, per_voxel_step, short_of_samples);
  resolve_alpha_warmup(config.training, g);
  config.encoding.log2_table_size = config.encoding.log2_table_for(short_of_samples);
  if (config.encoding.finest_resolution == 0) {
    const std::size_t largest = *std::max_element(g.volume_shape.begin(), g.volume_shape.end());
    config.encoding.finest_resolution =
        std::max(config.encoding.base_resolution, static_cast<int>(largest));
  }
  noise = model::reading_noise(scan);
  if (config.training.level_warmup_steps < 0) {
    config.training.level_warmup_steps =
        noise.relative >= config.training.level_warmup_noise ? config.training.steps / 24 : 0;
  }
  if (config.training.tail_average_steps < 0) {
    // The last learning-rate phase, and never more than the last quarter of the run.
    const int phase = std::min(config.training.decay_interval(), config.training.steps / 4);
    config.training.tail_average_steps =
        noise.relative >= config.training.level_warmup_noise ? phase : 0;
  }
  tail_average = {std::min(config.training.tail_average_steps, config.training.steps),
                  config.training.steps};
  // Before carving: a pixel stuck at the flat reads air through the object.
  if (config.training.stuck_elements) {
    stuck = model::stuck_elements(scan, noise.sigma);
    std::vector<float>& rho = scan.measurement.data;
    for (std::size_t e = 0; e < elements_per_view; ++e) {
      if (!stuck[e]) continue;
      ++stuck_count;
      for (std::size_t i = e; i < rho.size(); i += elements_per_view) rho[i] = NAN;
    }
  } else {
    stuck.assign(elements_per_view, 0);
  }
  // After the stuck elements: their steady readings are no detector gain.
  const std::vector<double> means = model::element_means(scan);
  stripe_rms = model::stripe_rms(means, g.n_u);
  if (g.is_3d()) {
    factor_evidence = model::factor_evidence(means, g);
    const AlphaModel asked = config.training.alpha_model;
    const bool by_evidence = factor_evidence.pixels > 0 &&
                             factor_evidence.explained >= config.training.alpha_factor_evidence;
    if (asked == AlphaModel::kRowsTimesColumns || (asked == AlphaModel::kAuto && by_evidence)) {
      alpha_model = AlphaModel::kRowsTimesColumns;
    }
  }
  responses = model::ResponseMap(elements_per_view);
  if (config.training.partial_responses && alpha_model != AlphaModel::kRowsTimesColumns) {
    response_changes =
        model::find_response_changes(scan.measurement, {config.training.partial_response_sigmas});
    responses = model::ResponseMap(elements_per_view, g.n_views(), response_changes);
  }
  layout = model::make_layout(g.is_3d() ? 3 : 2, config.encoding, config.network, responses.slots(),
                              alpha_model == AlphaModel::kRowsTimesColumns ? g.n_v : 0);
  occupancy.inside.assign(shape_size(g.volume_shape), 1);
  if (config.training.skip_air) {
    occupancy = model::carve_occupancy(
        scan, segments, config.training.sample_spacing,
        model::occupancy_settings(config.training, g, config.engine, std::move(device)));
    if (occupancy.carved) samples_kept = occupancy.samples_kept;
  }
  voxels_per_ray = sampled_voxels_per_ray(occupancy, segments);
  const double most_voxels = config.training.smooth_decay_max_voxels_per_ray;
  if (most_voxels > 0.0 && voxels_per_ray > most_voxels) config.training.lr_decay_smooth = false;
  alpha_rate = config.training.alpha_lr_scale;
  if (config.training.alpha_stripe_scale > 0) {
    alpha_rate *= std::min(1.0, stripe_rms / config.training.alpha_stripe_scale);
  }
  seed = static_cast<std::uint32_t>(config.training.seed ^ (config.training.seed >> 32));
  invalid_readings.assign(responses.slots(), 0);
  // A filled row's elements read nothing themselves: their readings count as invalid, as those
  // with no finite reading. Their filled values are finite, so they are no unread slots (they
  // start at beta0, not at unread_beta0). A bound is a reading.
  std::vector<bool> filled(elements_per_view, false);
  for (const std::size_t r : filled_rows) {
    std::fill(filled.begin() + static_cast<std::ptrdiff_t>(r * g.n_u),
              filled.begin() + static_cast<std::ptrdiff_t>((r + 1) * g.n_u), true);
  }
  std::vector<std::uint8_t> read(responses.slots(), 0);
  const std::vector<float>& rho = scan.measurement.data;
  for (std::size_t ray = 0; ray < rho.size(); ++ray) {
    const std::size_t slot = responses.slot(ray % elements_per_view, ray / elements_per_view);
    if (model::is_unread(rho[ray]) || filled[ray % elements_per_view]) ++invalid_readings[slot];
    if (!model::is_unread(rho[ray])) read[slot] = 1;
  }
  for (std::size_t slot = 0; slot < read.size(); ++slot) {
    if (!read[slot]) unread_slots.push_back(slot);
  }
}

std::vector<float> TrainingSetup::initial_parameters() const {
  if (!initial.empty()) return initial;
  std::vector<float> p = model::initial_parameters(layout, config.training.seed);
  for (const std::size_t slot : unread_slots) {
    p[layout.beta_offset + slot] = static_cast<float>(config.training.unread_beta0);
  }
  return p;
}

double TrainingSetup::learning_rate(int step) const {
  const TrainingConfig& t = config.training;
  const int interval = t.decay_interval();
  const double phases = t.lr_decay_smooth ? static_cast<double>(step) / interval
                                          : static_cast<double>(step / interval);
  return t.learning_rate * std::pow(t.lr_decay, phases);
}

std::vector<float> TrainingSetup::level_weights(int step) const {
  const int k = config.training.level_warmup_steps;
  std::vector<float> w(static_cast<std::size_t>(layout.levels), 1.0f);
  if (k <= 0) return w;
  for (int l = 1; l < layout.levels; ++l) {
    const double t = (static_cast<double>(step) - (l - 1) * static_cast<double>(k)) / k;
    w[static_cast<std::size_t>(l)] = static_cast<float>(std::clamp(t, 0.0, 1.0));
  }
  return w;
}

bool TrainingSetup::holds_all_alpha(int step) const {
  const TrainingConfig& t = config.training;
  // Asked every step (adam_settings): past the warm-up, before the views are looked at.
  if (step >= t.alpha_warmup_steps) return false;
  const Geometry& g = scan.geometry;
  return !(t.alpha_warmup_broad_px > 0.0 && !g.is_3d() && reads_lines_twice(g));
}

bool TrainingSetup::holds_broad_even_alpha(int step) const {
  return step < config.training.alpha_warmup_steps && !holds_all_alpha(step);
}

std::optional<model::BroadEvenHold> TrainingSetup::broad_even_hold(
    std::span<const float> initial_alpha) const {
  if (!holds_broad_even_alpha(0) || layout.factored_alpha()) return std::nullopt;
  return model::BroadEvenHold(scan.geometry, config.training.alpha_warmup_broad_px,
                              initial_alpha);
}

model::AdamSettings TrainingSetup::adam_settings(int step) const {
  const TrainingConfig& t = config.training;
  const double lr = learning_rate(step);
  return {lr,
          layout.alpha_offset,
          holds_all_alpha(step) ? 0.0 : lr * alpha_rate,
          layout.beta_offset,
          lr * t.beta_lr_scale,
          t.adam_beta1,
          t.adam_beta2,
          t.adam_epsilon,
          t.sparse_adam ? layout.grid_params : 0};
}

}  // namespace riner::detail
