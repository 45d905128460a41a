// Settings of a Riner reconstruction (METHOD.md §2): the hash-grid encoding, the MLP, the
// forward model and the training schedule. Defaults are the measured best trade-off of run time
// against error (docs/history/RESULTS.md); the paper's values are reachable through the same
// fields.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "riner/engine.hpp"
#include "riner/execution_plan.hpp"
#include "riner/residual_detail.hpp"
#include "riner/ring_correction.hpp"

namespace riner {

// Multiresolution grid (instant-NGP): level l has scale base_resolution * b^l - 1 with b chosen
// so that the last level reaches finest_resolution; a level is dense while it fits in
// 2^log2_table_size entries and spatially hashed above that.
struct EncodingConfig {
  // 0: the scan's (filled in by the Reconstructor): kLog2TableVolume for a volume short of
  // samples (training.min_samples_per_voxel), kLog2TableSlice otherwise. Such a volume's step
  // is held by its table: Adam and the gradient scatter touch a few entries in every cache line
  // of it, so on a CPU a step costs in proportion to the table (the chest CT at 12 000 steps:
  // 2^18 100 s, 2^16 41 s, at the same 32.7 dB), and the volume gains from steps, not entries
  // (docs/history/RESULTS.md, issue 34). A thin slab, sampled enough, keeps the slice's table
  // (2^16 there: -1.8 dB).
  static constexpr int kScanTable = 0;
  static constexpr int kLog2TableSlice = 18;
  static constexpr int kLog2TableVolume = 16;
  int levels = 8;
  int features = 2;  // per level
  int log2_table_size = kScanTable;
  int base_resolution = 16;
  int finest_resolution = 0;  // 0: the grid's largest side (one vertex per voxel at the top)

  // volume: a volume short of samples (TrainingConfig::min_samples_per_voxel).
  int log2_table_for(bool volume) const {
    if (log2_table_size != kScanTable) return log2_table_size;
    return volume ? kLog2TableVolume : kLog2TableSlice;
  }
};

// input (levels * features) -> [width, ReLU] x hidden_layers -> 1, linear output.
struct NetworkConfig {
  int width = 32;  // a multiple of 16 (the kernels hold hidden layers in float16 vectors)
  int hidden_layers = 1;
};

// How the data term weighs the batch's rays. Element mean: each detector element's term is the
// mean |residual| of its rays in the batch, so the balance against the -lambda beta^2 term does
// not depend on batch size or sampler; mean: the mean over all rays (the authors' earlier code);
// sum: the sum over rays (the paper's formula).
enum class DataTerm { kElementMean, kMean, kSum };

enum class Sampler {
  kViewsTimesElements,  // the paper's: random views x a run of adjacent random elements
  kUniform,             // rays drawn uniformly over (view, element)
  kMixed,               // both in one batch: uniform rays for the image, a views x elements
                        // block that shows a few elements from many views for alpha and beta
  kEven,                // every detector element (pixel in 3D) equally often: the elements in
                        // a shuffled order that visits each once per epoch, each ray at a
                        // random view; alpha and beta of every element learn from as many rays
};

// What alpha is made of in 3D. Per element: one response per detector pixel (the paper's).
// Rows x columns: alpha(r, c) = row factor r times column factor c (kernels/alpha_factors.cl),
// rows + columns numbers instead of rows x columns, for detectors whose gains vary by readout
// line or column amplifier. Auto: rows x columns when the measurement's stripe pattern is
// explained by row and column factors (model/factor_evidence.hpp), per element otherwise.
// A 2D scan's detector is one row, where the two are the same: it keeps per element.
enum class AlphaModel { kAuto, kPerElement, kRowsTimesColumns };

// training.air_fbp_check: auto is on in 2D and off in 3D, where the FDK's ring and cone-beam
// artifacts in the air read as object (the paper's 3D head: 0.32 -> 0.41 of the grid sampled).
enum class AirFbpCheck { kAuto, kOn, kOff };

struct TrainingConfig {
  // -1: the scan's (kSteps2d or kSteps3d, filled in by the Reconstructor), raised for a large
  // slice by min_draws_per_ray and for a volume by min_samples_per_voxel. kSteps3d is the
  // floor for a slab of a few slices; a whole volume at the paper's 3D protocol gets ~93 000
  // (docs/history/RESULTS.md, issue 34).
  static constexpr int kScanSteps = -1;
  static constexpr int kSteps2d = 24000;
  static constexpr int kSteps3d = 12000;
  int steps = kScanSteps;
  Sampler sampler = Sampler::kEven;
  // Uniform, even and mixed samplers; 0: the execution plan's (riner/execution_plan.hpp).
  int rays_per_step = 0;
  // A slice's steps, when left to the scan (steps -1), grow past kSteps2d until each ray is
  // drawn this often over the run. 10: half the paper-size slice's 21 (24 000 x 160 rays over
  // 360 x 500 rays). A 2048-column Shepp-Logan slice: 31.76 dB and edges 0.84 of the truth's
  // at 1.3 draws, 38.44 and 0.97 at 10 (docs/history/RESULTS.md, issue 29 item 2); the 2D scans in
  // ../shared (9.5-33 draws on a CPU) change by at most 5%. 0: off. 2D only.
  double min_draws_per_ray = 10.0;
  // A volume is short of samples when kSteps3d steps (in batches of at most 160 rays) would
  // sample its grid's voxels fewer than this many times each (the rays' samples inside the
  // grid, air included). Its steps, when left to the scan (steps -1), then grow until they do,
  // and it trains with the volume's table (log2_table_size 0). A 3D field is short of draws,
  // not of entries: the chest CT at the paper's protocol gains 1-2 dB for each doubling of its
  // steps (docs/history/RESULTS.md, issue 34). A slab of a few slices is sampled ~1000 times at
  // kSteps3d and trains as before. 0: off (no volume is short).
  double min_samples_per_voxel = 200.0;
  int views_per_step = 40;      // views x elements sampler
  int elements_per_step = 2;    // views x elements sampler: adjacent elements
  double sample_spacing = 1.5;  // along each ray, in voxels (the paper uses a fixed interval)
  bool jitter = false;          // stratified random offsets while training (midpoints if off)
  bool circle_region = false;   // sample the inscribed circle instead of the whole grid
  // Skip the air around the object (model/occupancy.hpp): voxels that air_min_views views
  // certify as air (the mean of three neighbouring readings within air_noise_sigmas noise
  // sigmas of their offsets, over the voxel's shadow widened by air_centre_tolerance_px) and that
  // the FBP does not see as object (air_fbp_check) are not sampled and read 0 in the image;
  // air_margin_px voxels around the rest stay. summary.json reports the rays through the skipped
  // air that read above it.
  bool skip_air = true;
  double air_noise_sigmas = 4.0;
  int air_margin_px = 4;
  int air_min_views = 3;
  double air_centre_tolerance_px = 0.0;
  AirFbpCheck air_fbp_check = AirFbpCheck::kAuto;
  double learning_rate = 1e-3;
  // The rate is multiplied by lr_decay every lr_decay_steps steps; 0: every steps / 4, so the
  // schedule stretches with the budget (--steps 12000 halves every 3000).
  int lr_decay_steps = 0;
  double lr_decay = 0.5;
  // Smooth: the rate decays continuously, lr_decay per lr_decay_steps (learning_rate *
  // lr_decay^(step / interval)), instead of in steps at each interval; the intervals still
  // mark the phases (beta's warm-up, tail averaging, the plateau test). On DeepLesion slices
  // 0-3 at 24 000 steps: 39.18 dB in steps, 39.62 smooth (docs/history/RESULTS.md, issue 29).
  bool lr_decay_smooth = true;
  // ... but not on a scan with too few readings for its unknowns: where each ray crosses more
  // than this many sampled voxels on average (few views for the grid) the rate halves in steps,
  // whose higher rate keeps such a scan's edges. Measured (docs/history/RESULTS.md, issue 29):
  // the 1100-column faint square of 343 views (1.56 voxels per ray) 35.40 dB smooth, 37.14 in
  // steps; a 400-view Shepp-Logan over 180 degrees (1.52) 39.72, 41.19; DeepLesion from 60
  // fan-beam views (3.1) 34.40, 35.15; from 90 (2.1) 37.96 both; from 180 (1.03) 43.09, 42.38;
  // the paper's protocols (0.51) and the shared real scans (0.29-1.18) stay smooth. 0: smooth on
  // every scan.
  double smooth_decay_max_voxels_per_ray = 1.25;
  double adam_beta1 = 0.9;
  double adam_beta2 = 0.99;
  double adam_epsilon = 1e-15;
  // Lazy Adam over the hash grid: entries the step's batch does not touch keep their value and
  // moments instead of decaying and drifting (model/adam_settings.hpp).
  bool sparse_adam = false;
  double lambda = 0.01;  // weight of the -beta^2 term
  // alpha0 and beta0 learn at learning_rate times these scales. alpha0 stays at its initial
  // value for alpha_warmup_steps (whichever of alpha and the field learns a ring first keeps
  // it: docs/history/RESULTS.md, issue 13). beta0 of an element with no invalid (non-finite)
  // reading stays put for beta_warmup_steps (-1: the first learning-rate phase): while the image is
  // still far off, every element's residual is large and beta would switch live elements off,
  // most where rays are longest; an element with invalid readings learns from the start (the
  // readings are the evidence).
  double alpha_lr_scale = 1.0;
  // alpha's rate follows the evidence: it is further multiplied by min(1, stripe / this), where
  // stripe is the RMS of the element-to-element offsets of the measurement's per-element means
  // (model/stripe_evidence.hpp). Adam moves a parameter by about its rate whatever the
  // gradient, so an alpha as fast as the field on a detector whose offsets are 0.002 learns
  // the object's edges instead (the halo of docs/history/RESULTS.md, issue 13). 0 turns it off.
  double alpha_stripe_scale = 0.05;
  // Elements whose readings stay steady while their neighbours on both sides vary (a dead,
  // hot or stuck pixel, row or column; model/stuck_elements.hpp) are taken for dead before
  // training: their readings count as invalid, like non-finite ones.
  bool stuck_elements = true;
  // Partial rings: elements (pixels) whose response changes part-way through the scan (a jump of
  // their reading against their neighbours', held for views / 12 views (near the scan's ends,
  // what is left of them), at least
  // partial_response_sigmas times the noise) or that die part-way (a run of non-finite
  // readings) get an alpha0 and a beta0 per segment of views instead of one
  // (model/response_changes.hpp; in 3D each detector row's sinogram on its own, and not with
  // alpha by rows x columns). A scan without such evidence trains exactly as before.
  bool partial_responses = true;
  double partial_response_sigmas = 12.0;
  AlphaModel alpha_model = AlphaModel::kAuto;
  // Auto: rows x columns when the factors explain at least this fraction of the stripe
  // pattern's energy (model/factor_evidence.hpp).
  double alpha_factor_evidence = 0.9;
  double beta_lr_scale = 3.0;
  // beta0 of a response slot that reads nothing (no finite reading, no bound: a dead element, a
  // stuck one, a changing element's views after it died); the paper starts every element at 1.
  // There its readings, counted as 0, pull the field down along its rays until beta falls: where
  // such a ray crosses metal, held only from below by its bounds, the field took that as
  // streaks (three dead elements across a metal disc's trace: the error outside it x5).
  double unread_beta0 = -12.0;
  // -1: the scan's: kWideAlphaWarmup steps on a slice whose detector row has at least
  // kWideDetectorElements elements (not after a warm start), 0 otherwise. Before the field has
  // drawn the object, every element whose rays cross it reads more than the field gives, and
  // alpha takes that offset; its part that is even about the axis has the same readings as a
  // radially symmetric image, so nothing in the data takes it back, and it stays a broad ring
  // band. At 1024 columns that band was most of DeepLesion's error: 300 steps of a still alpha
  // gave +0.87 and +1.23 dB (slices 0, 3); at 512 columns +0.02, on the ten 256^2 paper-protocol
  // slices -0.21 on average (the field takes narrow rings meanwhile), so smaller detectors keep
  // 0 (docs/history/RESULTS.md, issue 29).
  static constexpr int kScanAlphaWarmup = -1;
  static constexpr int kWideAlphaWarmup = 300;
  static constexpr std::size_t kWideDetectorElements = 1000;
  int alpha_warmup_steps = kScanAlphaWarmup;
  // During alpha_warmup_steps: 0 holds all of alpha; > 0 holds only its part that is even about
  // the axis and broader than a Gaussian of this sigma (grid pixels at the axis), and the rest
  // learns from the first step (model/broad_even_hold.hpp), on a slice whose views read each
  // line twice (a full turn, not a half acquisition); a 180-degree scan and a volume hold all.
  // 3 against all: DeepLesion at 1024 columns +0.19 / -0.28 / +0.31 dB (slices 3, 0, 1), the
  // Shepp-Logan +0.18 (1024) and +0.37 (2048), the 1100-column faint square over 360 degrees
  // +0.70, over 180 -1.45 (a 180-degree Shepp-Logan +0.30); sigma 1, 8 and 16 no better
  // (docs/history/RESULTS.md).
  double alpha_warmup_broad_px = 3.0;
  int beta_warmup_steps = -1;  // -1: the first learning-rate phase (decay_interval())
  // Coarse to fine: when > 0, level l >= 1 of the encoding fades in over steps
  // [(l - 1) k, l k] with k = level_warmup_steps (its features are scaled by 0 .. 1), so the
  // image can hold fine structure, rings included, only after alpha has had time to explain
  // the per-element offsets.
  // -1: by the noise evidence (model/noise_evidence.hpp): steps / 24 when the readings' noise
  // is at least level_warmup_noise of their 99th percentile, else 0. On the noisy real scans
  // (4e-3 to 7e-3) the finest levels draw the noise as sharp specks before the coarse ones
  // hold the image; the paper's simulated scans (1e-4) keep their training as it was. Longer
  // warm-ups (steps / 12) leave over- and undershoots at sharp edges (docs/history/RESULTS.md).
  int level_warmup_steps = -1;
  double level_warmup_noise = 0.001;
  // Tail averaging (model/tail_average.hpp): the image, alpha and beta come from the mean of the
  // parameters over the last tail_average_steps steps (a snapshot every 10) instead of the last
  // step's. -1: the last learning-rate phase (at most a quarter of the steps) when the readings
  // are noisy (as for level_warmup_steps), else 0. On the noisy real scans the last iterate draws
  // the last batches' noise as specks; on the paper's simulations the field still sharpens in the
  // last phase and its mean lags (DeepLesion -0.3 dB), so they keep the last iterate.
  int tail_average_steps = -1;
  // Warm start (training/warm_start.hpp): "off", or a classical stripe filter of
  // riner/destripe.hpp ("normalise", "sorting", "filtering", "fitting", "wavelet", "large",
  // "dead", "all"). alpha0
  // starts from the response the filter read off the scan and the field from a fit of
  // warm_start_steps steps to the FBP of the destriped scan, so that training begins where a
  // classical answer ends.
  // With a warm start, steps -1 is a third of the scan's steps and the learning rate is scaled
  // by warm_start_lr_scale: the field starts near an answer, and the full rate's first Adam
  // steps (each parameter moved by about the rate) would throw the fit away. Measured on
  // DeepLesion slice 0 at 8000 steps: 1e-4 38.20 dB, 2e-4 38.59, 3e-4 38.05, 1e-3 37.98 (cold:
  // 36.99; docs/history/RESULTS.md, issue 31). Under the smooth decay, from `wavelet` on the
  // ten DeepLesion slices at 8000 steps: a fit of 500 steps 38.96 dB (2.9 s of set-up), of
  // 1000 steps 39.18 (5.1 s), but on the noisy neutron360 the longer fit copies the FBP's
  // specks into the image (12.6 per 10^4 pixels against 2.1); rate scale 0.15 / 0.3 on slices
  // 0-3: -0.1 / -0.4 dB.
  std::string warm_start = "off";
  int warm_start_steps = 500;
  double warm_start_lr_scale = 0.2;
  // Stop on a plateau instead of at `steps`: in the last learning-rate phase, every
  // plateau_window steps (0: a quarter of the phase), training ends when the mean data loss of
  // the latest window is less than plateau_tolerance (relative) below the window's before.
  bool stop_on_plateau = false;
  int plateau_window = 0;
  double plateau_tolerance = 0.003;
  // Ring prior: weight of the squared view-averaged curvature of the model's projections across
  // adjacent elements of the views x elements block (kernels/riner_step.cl). Needs the
  // views-x-elements or mixed sampler with elements_per_step >= 3; 0 turns it off.
  double ring_lambda = 0.0;
  DataTerm data_term = DataTerm::kElementMean;
  // Multiplies the data term. With the element mean, an element is pushed towards beta = 0 when
  // the mean |residual| of its rays exceeds 2 lambda beta / data_weight: 0.1 at the default
  // 0.2, above what alpha errors leave on live elements, below a dead element's.
  double data_weight = 0.2;
  // When > 0, the threshold of an element whose readings are all finite is also at least this
  // many times the batch's median ray mismatch (lambda is raised to data_weight *
  // relative_beta_threshold * median / 2 where that is larger, step by step), so a loose fit (a
  // noisy scan, a dense edge still being learnt at 10^3 columns) does not switch live elements
  // off: 39 of 1100 on a simulated neutron square with 2 dead at 0 (441 and the square's middle
  // with 640 rays per step), exactly the 2 at 20. An element with a non-finite reading (a
  // simulated dead one, zero counts) keeps lambda, so it is still switched off as before
  // (docs/history/RESULTS.md, issue 29).
  double relative_beta_threshold = 20.0;
  std::uint64_t seed = 0;

  // Steps for a scan of this dimension: `steps`, or the dimension's default when it is -1.
  int steps_for(bool is_3d) const {
    if (steps != kScanSteps) return steps;
    return is_3d ? kSteps3d : kSteps2d;
  }
  // Needs `steps` resolved (steps_for); the Reconstructor's config always is.
  int decay_interval() const {
    return lr_decay_steps > 0 ? lr_decay_steps : std::max(1, steps / 4);
  }
  int beta_warmup() const { return beta_warmup_steps >= 0 ? beta_warmup_steps : decay_interval(); }
  int plateau_window_steps() const {
    return plateau_window > 0 ? plateau_window : std::max(1, decay_interval() / 4);
  }
};

// After training, 2D: the ring corrections (riner/ring_correction.hpp) move the rings the data
// cannot tell from detector offsets out of the image: first wherever air shows them, then the
// narrow ones inside the object, from the image's radial slopes; then the broad ones back from
// alpha, whose broad structure across the detector is not a detector's; then the narrow ones
// again, which the broad structure hid.
struct RingCorrectionConfig {
  bool air_reference = true;
  AirRingSettings air;
  bool gradient_reference = true;
  GradientRingSettings gradient;
  bool response_reference = true;
  ResponseRingSettings response;
  // The gradient correction once more after the response correction (when both are on): the
  // first pass keeps the edges of broad structure, so the narrow rings beside them wait until
  // the response correction has taken it (docs/history/RESULTS.md, issue 13).
  bool gradient_after_response = true;
  // 2D: the gradient correction once more after the readings' detail is given back (when it
  // was): the detail sharpens the edges that cross a circle, so the flattest half of its points
  // holds fewer of them and the rings the field kept stand out (docs/history/RESULTS.md, issue 29).
  bool gradient_after_detail = true;
  // Before all of them, objects centred on the axis that training put into alpha go back into
  // the image (correct_rings_from_mirrors): a tube's wall, a cylinder's edge
  // (docs/history/RESULTS.md, issue 32).
  bool mirror_reference = true;
  MirrorRingSettings mirror;
  // Parallel-beam volumes: the three above, slice by slice (riner/volume_ring_correction.hpp).
  // Off by default: the 3D field holds few rings; on the simulated parallel-beam head the chain
  // costs 0.13 dB, and on the real savu_proj3d it raises the ring index (docs/history/RESULTS.md).
  bool slice_by_slice = false;
};

struct RinerConfig {
  EncodingConfig encoding;
  NetworkConfig network;
  TrainingConfig training;
  RingCorrectionConfig rings;
  // After the ring corrections, the readings' detail the field has not learnt, through FBP
  // (riner/residual_detail.hpp).
  ResidualDetailSettings residual_detail;
  PlanConfig plan;  // how the OpenCL engine shapes its work (riner/execution_plan.hpp)
  Engine engine = Engine::kOpenCL;

  // InputError naming the first impossible setting.
  void validate() const;

  // Reads the settings a JSON object names ({"encoding": {"levels": 10}, "training": {...}});
  // missing keys keep their current values, unknown keys are an InputError.
  void update_from_json(std::string_view json_text, std::string_view source = "config");
  std::string to_json() const;
  // One setting by its JSON name ("training.steps") from text: a JSON value (12000, true, 0.3)
  // or a bare word for a named choice (uniform). InputError for an unknown name or bad value.
  void set(std::string_view name, std::string_view value);

  // Every setting a config file can hold, in the order config.json lists them.
  struct SettingInfo {
    std::string name;           // "training.steps"
    std::string type;           // bool, integer, number or choice
    std::string allowed;        // "in 0..10000000", "one of uniform, mixed", ...
    std::string default_value;  // as JSON
    std::string help;
  };
  static std::vector<SettingInfo> settings();

  // The paper's settings: L=10, T=2^10, F=8, N_min=2, b=2, width 128, 80 rays per step
  // (40 views x 2 elements), lr 1e-3 halved every 1000 steps, 4000 steps, summed data term;
  // no air-referenced ring correction.
  static RinerConfig paper();
};

const char* sampler_name(Sampler sampler);
// Whether the sampler draws a views x elements block (what ring_lambda's prior needs).
constexpr bool draws_block(Sampler s) {
  return s == Sampler::kViewsTimesElements || s == Sampler::kMixed;
}
const char* data_term_name(DataTerm term);
// "auto", "per-element", "rows-x-columns".
const char* alpha_model_name(AlphaModel model);
const char* air_fbp_check_name(AirFbpCheck check);

}  // namespace riner
