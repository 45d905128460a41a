#include "settings/config_settings.hpp"

#include <algorithm>

#include "rings/ring_settings.hpp"

namespace riner {

namespace {

using settings::closed;
using settings::closed_open;
using settings::enum_choice;
using settings::field;
using settings::open;
using settings::open_closed;
using settings::string_choice;
using C = RinerConfig;
using E = EncodingConfig;
using N = NetworkConfig;
using T = TrainingConfig;
using P = PlanConfig;
using R = RingCorrectionConfig;
using Table = std::vector<settings::Setting<C>>;

constexpr double kMaxSteps = 1e7;

void add_encoding(Table& t) {
  t.push_back(
      field<C>("encoding", "levels", closed(1, 32), "hash-grid levels", &C::encoding, &E::levels));
  t.push_back(field<C>("encoding", "features", closed(1, 8), "features per level", &C::encoding,
                       &E::features));
  t.push_back(field<C>("encoding", "log2_table_size", closed(0, 26),
                       "log2 of each level's table entries (dense while the level fits); 0: the "
                       "scan's, 16 for a volume short of samples (min_samples_per_voxel), else 18",
                       &C::encoding, &E::log2_table_size));
  t.push_back(field<C>("encoding", "base_resolution", closed(2, 65536), "coarsest level's scale",
                       &C::encoding, &E::base_resolution));
  t.push_back(field<C>("encoding", "finest_resolution", closed(0, 1 << 20),
                       "finest level's scale, >= base_resolution; 0: the grid's largest side",
                       &C::encoding, &E::finest_resolution));
}

void add_network(Table& t) {
  t.push_back(field<C>("network", "width", closed(16, 256), "hidden width, a multiple of 16",
                       &C::network, &N::width));
  t.push_back(field<C>("network", "hidden_layers", closed(1, 4), "hidden layers", &C::network,
                       &N::hidden_layers));
}

// How a step samples rays along them.
void add_training_sampling(Table& t) {
  t.push_back(field<C>("training", "steps", closed(-1, kMaxSteps),
                       "training steps; -1: the scan's, 24000 in 2D and 12000 in 3D or more "
                       "(min_draws_per_ray, min_samples_per_voxel)",
                       &C::training, &T::steps));
  t.push_back(enum_choice<C>(
      "training", "sampler",
      {Sampler::kUniform, Sampler::kViewsTimesElements, Sampler::kMixed, Sampler::kEven},
      sampler_name,
      "how a step's rays are drawn; even: every detector element equally often, each at a random "
      "view",
      &C::training, &T::sampler));
  t.push_back(field<C>("training", "rays_per_step", closed(0, 1 << 20),
                       "uniform, even and mixed samplers' rays per step; 0: the execution "
                       "plan's",
                       &C::training, &T::rays_per_step));
  t.push_back(field<C>("training", "min_draws_per_ray", closed_open(0, 1e6),
                       "2D, steps -1: the steps grow until each ray is drawn this often in "
                       "batches of at most 160 rays (a larger batch keeps those steps); 0: off",
                       &C::training, &T::min_draws_per_ray));
  t.push_back(field<C>("training", "min_samples_per_voxel", closed_open(0, 1e9),
                       "3D: a volume whose voxels 12000 steps of at most 160 rays sample fewer times "
                       "each is short of samples: its steps (-1) grow until they do, its table "
                       "is the volume's; 0: off",
                       &C::training, &T::min_samples_per_voxel));
  t.push_back(field<C>("training", "views_per_step", closed(1, 65536),
                       "views x elements sampler: views", &C::training, &T::views_per_step));
  t.push_back(field<C>("training", "elements_per_step", closed(1, 65536),
                       "views x elements sampler: adjacent elements", &C::training,
                       &T::elements_per_step));
  t.push_back(field<C>("training", "sample_spacing", open_closed(0.01, 100),
                       "spacing of the samples along a ray, in voxels", &C::training,
                       &T::sample_spacing));
  t.push_back(field<C>("training", "jitter", {}, "stratified random sample offsets", &C::training,
                       &T::jitter));
  t.push_back(field<C>("training", "circle_region", {},
                       "sample the inscribed circle instead of the whole grid", &C::training,
                       &T::circle_region));
  t.push_back(field<C>("training", "skip_air", {},
                       "do not sample the air the readings certify (it reads 0)", &C::training,
                       &T::skip_air));
  t.push_back(field<C>("training", "air_noise_sigmas", closed(0.5, 100),
                       "skip_air: a reading within this many noise sigmas of its offset is air",
                       &C::training, &T::air_noise_sigmas));
  t.push_back(field<C>("training", "air_margin_px", closed(0, 64),
                       "skip_air: voxels kept around what is not air", &C::training,
                       &T::air_margin_px));
  t.push_back(field<C>("training", "air_min_views", closed(1, 100000),
                       "skip_air: views that must certify a voxel as air", &C::training,
                       &T::air_min_views));
  t.push_back(
      field<C>("training", "air_centre_tolerance_px", closed(0, 64),
               "skip_air: each view's shadow of a voxel widened by this many pixels (a centre of "
               "rotation off by as many shrinks the carved region's outline)",
               &C::training, &T::air_centre_tolerance_px));
  t.push_back(enum_choice<C>(
      "training", "air_fbp_check", {AirFbpCheck::kAuto, AirFbpCheck::kOn, AirFbpCheck::kOff},
      air_fbp_check_name,
      "skip_air: keep every voxel the scan's FBP clearly sees as object; auto: in 2D (in 3D the "
      "FDK's artifacts read as object)",
      &C::training, &T::air_fbp_check));
}

// The optimiser, the schedule and the loss.
void add_training_schedule(Table& t) {
  t.push_back(field<C>("training", "learning_rate", open(0, 10), "Adam's learning rate",
                       &C::training, &T::learning_rate));
  t.push_back(field<C>("training", "lr_decay_steps", closed(0, kMaxSteps),
                       "steps between learning-rate decays; 0: steps / 4", &C::training,
                       &T::lr_decay_steps));
  t.push_back(field<C>("training", "lr_decay", open_closed(0, 1),
                       "factor of each learning-rate decay", &C::training, &T::lr_decay));
  t.push_back(field<C>("training", "lr_decay_smooth", {},
                       "the rate decays continuously (lr_decay per lr_decay_steps) instead of "
                       "in steps",
                       &C::training, &T::lr_decay_smooth));
  t.push_back(field<C>("training", "smooth_decay_max_voxels_per_ray", closed_open(0, 1e9),
                       "lr_decay_smooth: only where each ray crosses at most this many sampled "
                       "voxels on average (a scan with fewer views than its grid needs decays in "
                       "steps); 0: smooth on every scan",
                       &C::training, &T::smooth_decay_max_voxels_per_ray));
  t.push_back(field<C>("training", "adam_beta1", closed_open(0, 1), "Adam's beta1", &C::training,
                       &T::adam_beta1));
  t.push_back(field<C>("training", "adam_beta2", closed_open(0, 1), "Adam's beta2", &C::training,
                       &T::adam_beta2));
  t.push_back(field<C>("training", "adam_epsilon", open(0, 1), "Adam's epsilon", &C::training,
                       &T::adam_epsilon));
  t.push_back(field<C>("training", "sparse_adam", {},
                       "hash-grid entries the batch does not touch keep value and moments",
                       &C::training, &T::sparse_adam));
  t.push_back(field<C>("training", "lambda", closed_open(0, 1e6),
                       "weight of the -beta^2 term (dead-element mask)", &C::training, &T::lambda));
  t.push_back(field<C>("training", "alpha_lr_scale", closed_open(0, 1000),
                       "alpha's learning rate over the field's", &C::training, &T::alpha_lr_scale));
  t.push_back(field<C>("training", "alpha_stripe_scale", closed(0, 10),
                       "alpha's rate is further scaled by min(1, the measurement's stripe RMS / "
                       "this); 0: off",
                       &C::training, &T::alpha_stripe_scale));
  t.push_back(field<C>("training", "stuck_elements", {},
                       "elements steady over the views while their neighbours vary are dead "
                       "before training",
                       &C::training, &T::stuck_elements));
  t.push_back(field<C>("training", "partial_responses", {},
                       "alpha and beta per segment of views for elements whose response "
                       "changes or that die part-way (partial rings)",
                       &C::training, &T::partial_responses));
  t.push_back(field<C>("training", "partial_response_sigmas", closed(3, 1000),
                       "partial_responses: a change must jump this many noise sigmas", &C::training,
                       &T::partial_response_sigmas));
  t.push_back(enum_choice<C>(
      "training", "alpha_model",
      {AlphaModel::kAuto, AlphaModel::kPerElement, AlphaModel::kRowsTimesColumns}, alpha_model_name,
      "3D: alpha per detector pixel, or row x column factors; auto: by the stripe evidence",
      &C::training, &T::alpha_model));
  t.push_back(field<C>("training", "alpha_factor_evidence", closed(0, 1),
                       "alpha_model auto: row x column factors when they explain this fraction "
                       "of the stripe pattern",
                       &C::training, &T::alpha_factor_evidence));
  t.push_back(field<C>("training", "beta_lr_scale", closed_open(0, 1000),
                       "beta's learning rate over the field's", &C::training, &T::beta_lr_scale));
  t.push_back(field<C>("training", "unread_beta0", closed(-30, 30),
                       "beta0 of an element that reads nothing (a dead one): it starts "
                       "switched off (the paper: 1, as every element)",
                       &C::training, &T::unread_beta0));
  t.push_back(field<C>("training", "alpha_warmup_steps", closed(-1, kMaxSteps),
                       "alpha stays at its initial value for these steps; -1: 300 on a slice "
                       "whose detector row has at least 1000 elements, else 0",
                       &C::training, &T::alpha_warmup_steps));
  t.push_back(field<C>("training", "alpha_warmup_broad_px", closed(0, 1e6),
                       "alpha_warmup_steps hold only alpha's part even about the axis and "
                       "broader than a Gaussian of this sigma (grid pixels) where the views "
                       "read each line twice (a full turn); 0, a 180-degree scan or a volume: "
                       "all of alpha",
                       &C::training, &T::alpha_warmup_broad_px));
  t.push_back(field<C>("training", "beta_warmup_steps", closed(-1, kMaxSteps),
                       "beta of elements with valid readings stays put for these steps; -1: the "
                       "first learning-rate phase",
                       &C::training, &T::beta_warmup_steps));
  t.push_back(field<C>("training", "level_warmup_steps", closed(-1, kMaxSteps),
                       "coarse to fine: each finer level fades in over these steps; 0: off; -1: "
                       "steps / 24 when the readings are noisy (level_warmup_noise), else 0",
                       &C::training, &T::level_warmup_steps));
  t.push_back(field<C>("training", "level_warmup_noise", closed(0, 1),
                       "level_warmup_steps -1: coarse to fine when the readings' noise is at "
                       "least this fraction of their 99th percentile",
                       &C::training, &T::level_warmup_noise));
  t.push_back(field<C>("training", "tail_average_steps", closed(-1, kMaxSteps),
                       "the result is the mean of the parameters over these last steps; 0: the "
                       "last step's; -1: the last learning-rate phase when the readings are "
                       "noisy (level_warmup_noise), else 0",
                       &C::training, &T::tail_average_steps));
  t.push_back(string_choice<C>(
      "training", "warm_start",
      {"off", "normalise", "sorting", "filtering", "fitting", "wavelet", "large", "dead", "all"},
      "2D: start alpha from this classical stripe filter's response and the field from the FBP "
      "of its destriped scan; off: a cold start",
      &C::training, &T::warm_start));
  t.push_back(field<C>("training", "warm_start_steps", closed(1, 1000000),
                       "warm_start: steps fitting the field to the destriped FBP image",
                       &C::training, &T::warm_start_steps));
  t.push_back(field<C>("training", "warm_start_lr_scale", open_closed(0, 1),
                       "warm_start: the learning rate is scaled by this (and steps -1 is a third "
                       "of the scan's)",
                       &C::training, &T::warm_start_lr_scale));
  t.push_back(field<C>("training", "stop_on_plateau", {},
                       "stop in the last learning-rate phase when the loss stops falling",
                       &C::training, &T::stop_on_plateau));
  t.push_back(field<C>("training", "plateau_window", closed(0, kMaxSteps),
                       "stop_on_plateau: steps per window; 0: a quarter of a phase", &C::training,
                       &T::plateau_window));
  t.push_back(field<C>("training", "plateau_tolerance", closed_open(0, 1),
                       "stop_on_plateau: relative fall below which training stops", &C::training,
                       &T::plateau_tolerance));
  t.push_back(field<C>("training", "ring_lambda", closed_open(0, 1e9),
                       "weight of the ring prior (needs a views x elements block of >= 3 "
                       "elements); 0: off",
                       &C::training, &T::ring_lambda));
  t.push_back(enum_choice<C>(
      "training", "data_term", {DataTerm::kElementMean, DataTerm::kMean, DataTerm::kSum},
      data_term_name, "how the data term weighs the batch's rays", &C::training, &T::data_term));
  t.push_back(field<C>("training", "data_weight", open(0, 1e6), "multiplies the data term",
                       &C::training, &T::data_weight));
  t.push_back(field<C>("training", "relative_beta_threshold", closed_open(0, 1e6),
                       "> 0: an element whose readings are all finite stays on up to this many "
                       "times the batch's median ray mismatch, when that is above the "
                       "absolute threshold; 0: off",
                       &C::training, &T::relative_beta_threshold));
  t.push_back(field<C>("training", "seed", closed(0, 18446744073709551615.0),
                       "seed of the initial weights and the sampler", &C::training, &T::seed));
}

void add_rings(Table& t) {
  t.push_back(field<C>("rings", "air_reference", {},
                       "2D (3D: slice_by_slice): ring correction from the air", &C::rings,
                       &R::air_reference));
  for (const auto& s : rings::air_settings()) t.push_back(settings::lift<C>(s, &C::rings, &R::air));
  t.push_back(field<C>("rings", "gradient_reference", {},
                       "2D (3D: slice_by_slice): ring correction from the image's radial slopes",
                       &C::rings, &R::gradient_reference));
  for (const auto& s : rings::gradient_settings()) {
    t.push_back(settings::lift<C>(s, &C::rings, &R::gradient));
  }
  t.push_back(field<C>(
      "rings", "response_reference", {},
      "2D (3D: slice_by_slice): broad rings back from alpha's structure across the detector",
      &C::rings, &R::response_reference));
  for (const auto& s : rings::response_settings()) {
    t.push_back(settings::lift<C>(s, &C::rings, &R::response));
  }
  t.push_back(field<C>("rings", "gradient_after_response", {},
                       "the gradient correction again after the response correction (both on)",
                       &C::rings, &R::gradient_after_response));
  t.push_back(field<C>("rings", "gradient_after_detail", {},
                       "2D: the gradient correction again after the readings' detail is added "
                       "(when it is)",
                       &C::rings, &R::gradient_after_detail));
  t.push_back(field<C>("rings", "mirror_reference", {},
                       "2D (3D: slice_by_slice): objects on the axis back from alpha's even "
                       "structure that its odd part does not share",
                       &C::rings, &R::mirror_reference));
  for (const auto& s : rings::mirror_settings()) {
    t.push_back(settings::lift<C>(s, &C::rings, &R::mirror));
  }
  t.push_back(field<C>("rings", "slice_by_slice", {},
                       "parallel 3D: the corrections above, each slice with its detector row "
                       "(off: measured to cost 0.13 dB on a simulated head, more rings on savu)",
                       &C::rings, &R::slice_by_slice));
}

void add_residual_detail(Table& t) {
  using D = ResidualDetailSettings;
  t.push_back(field<C>("detail", "residual", {},
                       "after the ring corrections, add the FBP (FDK in cone beam) of what the "
                       "readings hold beyond the field, where the even and odd views agree it is "
                       "not noise",
                       &C::residual_detail, &D::enabled));
  t.push_back(field<C>("detail", "min_consistent_share", closed(0, 1),
                       "detail.residual: only when the even and odd views' FBPs of the residual "
                       "agree on this share of its energy",
                       &C::residual_detail, &D::min_consistent_share));
  t.push_back(field<C>("detail", "window_px", closed(1, 63),
                       "detail.residual: side of the square the noise gain is judged over (an even "
                       "side counts as the next odd one)",
                       &C::residual_detail, &D::window_px));
  t.push_back(field<C>("detail", "held_out_readings", closed(1, 1 << 30),
                       "detail.residual: the held-out check projects each half's detail at every "
                       "k-th view of the other half, k as large as leaves this many readings (a "
                       "volume's scan; a slice keeps every view)",
                       &C::residual_detail, &D::held_out_readings));
  t.push_back(field<C>("detail", "min_held_out_fall", closed(0, 1),
                       "detail.residual: only when each half's detail lowers the other half's "
                       "readings' misfit (less each element's mean) by this share times the "
                       "squared consistent share",
                       &C::residual_detail, &D::min_held_out_fall));
}

void add_plan(Table& t) {
  t.push_back(string_choice<C>("plan", "kind", {"auto", "cpu", "gpu"},
                               "the OpenCL engine's execution plan; auto: from the device",
                               &C::plan, &P::kind));
  t.push_back(string_choice<C>(
      "plan", "float_atomics",
      {"auto", "nvidia-ptx", "cl_ext_float_atomics", "amd-builtin", "compare-exchange"},
      "gpu plan: how the grid gradient adds floats", &C::plan, &P::float_atomics));
  t.push_back(field<C>("plan", "sample_group", closed(0, 4096),
                       "work-group of the per-sample kernels, in samples (the cpu plan's "
                       "work-items hold 16 each); 0: the device's choice",
                       &C::plan, &P::sample_group));
  t.push_back(field<C>("plan", "gradient_slices", closed(0, 65536),
                       "most work-groups of the MLP weight gradient; 0: the device's choice",
                       &C::plan, &P::gradient_slices));
  t.push_back(field<C>("plan", "grid_bands", closed(0, 4096),
                       "cpu plan: owners per encoding level; 0: the device's choice", &C::plan,
                       &P::grid_bands));
}

}  // namespace

const std::vector<settings::Setting<C>>& config_settings() {
  static const Table table = [] {
    Table t;
    add_encoding(t);
    add_network(t);
    add_training_sampling(t);
    add_training_schedule(t);
    add_rings(t);
    add_residual_detail(t);
    add_plan(t);
    t.push_back(enum_choice<C>("", "engine", {Engine::kOpenCL, Engine::kReference}, engine_name,
                               "opencl: the kernels; reference: their CPU twins (slow)",
                               &C::engine));
    return t;
  }();
  return table;
}

std::vector<std::string> config_sections() {
  std::vector<std::string> out;
  for (const auto& s : config_settings()) {
    if (std::find(out.begin(), out.end(), s.section) == out.end()) out.push_back(s.section);
  }
  return out;
}

}  // namespace riner
