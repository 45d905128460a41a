#include "riner/reconstructor.hpp"

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "cl/buffer.hpp"
#include "model/stopped_hull.hpp"
#include "riner/error.hpp"
#include "riner/ring_chain.hpp"
#include "riner/ring_correction.hpp"
#include "training/checkpoint.hpp"
#include "training/trainer.hpp"
#include "training/warm_start.hpp"

namespace riner {

struct Reconstructor::Impl {
  detail::TrainingSetup setup;
  model::BatchSampler sampler;
  std::unique_ptr<detail::Trainer> trainer;
  int steps = 0;
  double seconds = 0.0;
  double samples = 0.0;
  std::vector<LossRecord> history;
  bool plateaued = false;
  int resumed_at = 0;  // resume_from's step
  // The scan's and the settings' checkpoint fingerprints, computed at the first save or resume.
  std::optional<std::pair<std::uint64_t, std::uint64_t>> fingerprints;
  // Rays drawn so far per detector element (pixel in 3D): alpha and beta learn from these.
  std::vector<std::uint32_t> element_rays;
  // result() at `steps` training steps (it only changes with a step).
  std::optional<ReconstructionResult> result;
  int result_steps = -1;
  std::optional<WarmStartStats> warm_start;
  std::optional<Device> device;  // the OpenCL engine's (the residual detail's FBP runs there)

  Impl(Scan scan, RinerConfig config, std::optional<Device> device_ = std::nullopt)
      : setup(std::move(scan), std::move(config), device_),
        sampler(setup.scan.geometry, setup.config.training,
                setup.stuck_count > 0 ? setup.stuck : std::vector<std::uint8_t>{}),
        element_rays(setup.elements_per_view, 0),
        device(std::move(device_)) {}

  void drain() {
    for (LossRecord& r : trainer->drain_losses()) {
      if (!std::isfinite(r.data_loss)) {
        throw Error("training diverged at step " + std::to_string(r.step) +
                    " (the loss is not finite); try a smaller learning rate");
      }
      history.push_back(r);
    }
  }
};

namespace {

// The settings left to the device (rays_per_step = 0) filled in from its execution plan (those
// left to the scan: TrainingSetup).
RinerConfig resolved(RinerConfig config, const std::optional<ExecutionPlan>& plan) {
  if (config.training.rays_per_step == 0) {
    config.training.rays_per_step = plan ? plan->rays_per_step : ExecutionPlan::kCpuRaysPerStep;
  }
  return config;
}

// training.warm_start: the parameters training starts from, fitted with the engine's own trainer.
template <typename Impl>
void start_warm(Impl& impl, const detail::TrainerFactory& make_trainer,
                std::optional<Device> device) {
  if (!detail::wants_warm_start(impl.setup)) return;
  detail::WarmStart warm = detail::warm_start(impl.setup, make_trainer, std::move(device));
  impl.setup.initial = std::move(warm.parameters);
  impl.warm_start = warm.stats;
}

}  // namespace

Reconstructor::Reconstructor(Scan scan, RinerConfig config, std::optional<Device> device) {
  config.validate();
  if (config.engine == Engine::kReference) {
    impl_ = std::make_unique<Impl>(std::move(scan), resolved(std::move(config), std::nullopt));
    start_warm(*impl_, detail::make_reference_trainer, std::nullopt);
    impl_->trainer = detail::make_reference_trainer(impl_->setup);
    return;
  }
  Device d = device ? *device : Device::open();
  const ExecutionPlan plan = choose_execution_plan(d.info(), config.plan);
  impl_ = std::make_unique<Impl>(std::move(scan), resolved(std::move(config), plan), d);
  start_warm(
      *impl_,
      [&](const detail::TrainingSetup& fit) { return detail::make_opencl_trainer(fit, d, plan); },
      d);
  impl_->trainer = detail::make_opencl_trainer(impl_->setup, std::move(d), plan);
}

Reconstructor::~Reconstructor() = default;
Reconstructor::Reconstructor(Reconstructor&&) noexcept = default;
Reconstructor& Reconstructor::operator=(Reconstructor&&) noexcept = default;

void Reconstructor::step(int n) {
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < n; ++i) {
    const int index = impl_->steps;
    const model::Batch batch = impl_->sampler.batch(static_cast<std::uint32_t>(index));
    const std::size_t per_view = impl_->setup.elements_per_view;
    for (std::uint32_t r : batch.rays) {
      impl_->samples += impl_->setup.segments.count(r);
      ++impl_->element_rays[r % per_view];
    }
    impl_->trainer->step(index, batch);
    ++impl_->steps;
  }
  impl_->seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

namespace {

// training.stop_on_plateau: in the last learning-rate phase, the mean data loss of the latest
// window no longer `tolerance` below the window's before.
bool on_plateau(const TrainingConfig& t, const std::vector<LossRecord>& history) {
  if (!t.stop_on_plateau || t.steps <= 0) return false;
  const int interval = t.decay_interval();
  const int last_phase = (t.steps - 1) / interval * interval;
  const int window = t.plateau_window_steps();
  const int done = static_cast<int>(history.size());
  if (done - 2 * window < last_phase) return false;
  double latest = 0.0, before = 0.0;
  for (int i = done - window; i < done; ++i)
    latest += history[static_cast<std::size_t>(i)].data_loss;
  for (int i = done - 2 * window; i < done - window; ++i)
    before += history[static_cast<std::size_t>(i)].data_loss;
  return before - latest < t.plateau_tolerance * before;
}

// Whether the ring corrections change image and alpha: in 2D when any is on; in 3D only slice
// by slice (rings.slice_by_slice).
bool corrects_rings(const RinerConfig& c, const Geometry& g) {
  const bool any = c.rings.air_reference || c.rings.gradient_reference ||
                   c.rings.response_reference || c.rings.mirror_reference;
  return any && (!g.is_3d() || c.rings.slice_by_slice);
}

}  // namespace

void Reconstructor::run(const ProgressCallback& callback, int report_every) {
  const TrainingConfig& t = impl_->setup.config.training;
  const int total = t.steps;
  report_every = std::max(1, report_every);
  if (t.stop_on_plateau) {  // check at least once per window
    report_every = std::min(report_every, std::max(1, t.plateau_window_steps() / 4));
  }
  while (impl_->steps < total && !impl_->plateaued) {
    step(std::min(report_every, total - impl_->steps));
    impl_->drain();  // also the divergence check, once per block
    impl_->plateaued =
        static_cast<int>(impl_->history.size()) == impl_->steps && on_plateau(t, impl_->history);
    if (callback) {
      const double loss = impl_->history.empty() ? 0.0 : impl_->history.back().data_loss;
      if (!callback({impl_->steps, total, loss, impl_->seconds})) break;
    }
  }
}

int Reconstructor::steps_done() const { return impl_->steps; }

namespace {

// The run a checkpoint belongs to: the scan's fingerprint (readings and geometry) and the
// settings'; Impl keeps them after the first use, since neither changes between saves.
std::pair<std::uint64_t, std::uint64_t> run_fingerprints(const detail::TrainingSetup& setup) {
  const std::vector<float>& m = setup.scan.measurement.data;
  return {detail::fingerprint(setup.scan.geometry.to_json(),
                              detail::fingerprint({reinterpret_cast<const char*>(m.data()),
                                                   m.size() * sizeof(float)})),
          detail::fingerprint(setup.config.to_json())};
}

}  // namespace

void Reconstructor::save_checkpoint(const std::filesystem::path& path) {
  impl_->drain();
  if (!impl_->fingerprints) impl_->fingerprints = run_fingerprints(impl_->setup);
  detail::TrainingCheckpoint c;
  c.scan_fingerprint = impl_->fingerprints->first;
  c.settings_fingerprint = impl_->fingerprints->second;
  c.device = impl_->trainer->device_name();
  c.steps = impl_->steps;
  c.seconds = impl_->seconds;
  c.samples = impl_->samples;
  c.plateaued = impl_->plateaued;
  c.element_rays = impl_->element_rays;
  c.history = impl_->history;
  detail::ByteWriter state;
  impl_->trainer->save_state(state);
  c.trainer_state = state.bytes();
  detail::write_checkpoint(path, c);
}

void Reconstructor::resume_from(const std::filesystem::path& path) {
  const detail::TrainingCheckpoint c = detail::read_checkpoint(path);
  const std::string what = path.string() + ": ";
  if (!impl_->fingerprints) impl_->fingerprints = run_fingerprints(impl_->setup);
  if (c.scan_fingerprint != impl_->fingerprints->first) {
    throw InputError(what + "a checkpoint of another scan (other readings or geometry)");
  }
  if (c.settings_fingerprint != impl_->fingerprints->second) {
    throw InputError(what + "a checkpoint of other settings (steps, seed, --set, ... differ)");
  }
  if (c.device != impl_->trainer->device_name()) {
    throw InputError(what + "a checkpoint of training on " + c.device +
                     ": resume it there (this run is on " + impl_->trainer->device_name() + ")");
  }
  if (c.element_rays.size() != impl_->element_rays.size()) {
    throw InputError(what + "truncated or corrupt");
  }
  detail::ByteReader state(c.trainer_state, path.string());
  impl_->trainer->restore_state(state, c.steps);
  impl_->steps = c.steps;
  impl_->seconds = c.seconds;
  impl_->samples = c.samples;
  impl_->plateaued = c.plateaued;
  impl_->element_rays = c.element_rays;
  impl_->history = c.history;
  impl_->result.reset();
  impl_->result_steps = -1;
  impl_->resumed_at = c.steps;
}

Array Reconstructor::field_image() const {
  const Geometry& g = impl_->setup.scan.geometry;
  Array out(g.volume_shape);
  out.data = impl_->trainer->evaluate_grid();
  // The field learns mu times field_per_mu (a power of two; 1 for most scans).
  if (impl_->setup.field_per_mu != 1.0) {
    const auto per_mu = static_cast<float>(impl_->setup.field_per_mu);
    for (float& v : out.data) v /= per_mu;
  }
  model::fade_into_skipped_air(impl_->setup.occupancy, g.volume_shape,
                               model::air_taper_px(impl_->setup.config.training.air_margin_px),
                               out.data);
  return out;
}

ReconstructionResult Reconstructor::result() const {
  if (!impl_->result || impl_->result_steps != impl_->steps) {
    impl_->result = evaluate_result();
    impl_->result_steps = impl_->steps;
  }
  return *impl_->result;
}

namespace {

// Whether response slot `slot`, over `views` views, read nothing finite: an element's views
// after it died. Training never saw them, so its alpha and beta there are where they started.
bool slot_unread(const detail::TrainingSetup& setup, std::size_t slot, std::size_t views) {
  return setup.invalid_readings[slot] >= views;
}

// The changing elements' segments with their trained alpha and beta (parameters p); 0 and 0
// for a segment that read nothing (an element after it died: 1 and 1, "alive", before).
std::vector<ChangingElement> changing_elements_of(const detail::TrainingSetup& setup,
                                                  const std::vector<float>& p) {
  const model::ResponseMap& map = setup.responses;
  const model::ParameterLayout& l = setup.layout;
  std::vector<ChangingElement> out;
  for (const model::ResponseChange& c : setup.response_changes) {
    ChangingElement element{c.element, c.dies, {}};
    for (const model::ResponseMap::Segment& s : map.segments(c.element)) {
      if (slot_unread(setup, s.slot, s.views)) {
        element.segments.push_back({s.first_view, s.views, 0.0, 0.0});
        continue;
      }
      element.segments.push_back({s.first_view, s.views,
                                  std::max(p[l.alpha_offset + s.slot], 1e-8f),
                                  1.0 / (1.0 + std::exp(-p[l.beta_offset + s.slot]))});
    }
    out.push_back(std::move(element));
  }
  return out;
}

// max(alpha0, 1e-8) per element; a changing element's is its live segments' geometric mean by
// their views (all of them where none lives).
Array alpha_per_element(const detail::TrainingSetup& setup, const std::vector<float>& p) {
  const model::ParameterLayout& l = setup.layout;
  const Geometry& g = setup.scan.geometry;
  Array out(g.is_3d() ? std::vector<std::size_t>{g.n_v, g.n_u} : std::vector<std::size_t>{g.n_u});
  for (std::size_t e = 0; e < out.size(); ++e) out.data[e] = std::max(p[l.alpha_offset + e], 1e-8f);
  for (const ChangingElement& c : changing_elements_of(setup, p)) {
    double log_sum = 0.0, views = 0.0, all_log = 0.0, all_views = 0.0;
    for (const ResponseSegment& s : c.segments) {
      if (s.alpha <= 0.0) continue;  // read nothing
      all_log += std::log(s.alpha) * static_cast<double>(s.views);
      all_views += static_cast<double>(s.views);
      if (s.beta < Reconstructor::kDeadBelowBeta) continue;
      log_sum += std::log(s.alpha) * static_cast<double>(s.views);
      views += static_cast<double>(s.views);
    }
    out.data[c.element] = static_cast<float>(views > 0       ? std::exp(log_sum / views)
                                             : all_views > 0 ? std::exp(all_log / all_views)
                                                             : 1e-8);
  }
  return out;
}

// ReconstructionResult::alpha_by_view: each view's slot, scaled by what the ring corrections did
// to its element (trained -> corrected); empty when no element changes.
Array responses_by_view(const detail::TrainingSetup& setup, const std::vector<float>& p,
                        const Array& trained, const Array& corrected) {
  const model::ResponseMap& map = setup.responses;
  if (!map.varies()) return Array();
  const model::ParameterLayout& l = setup.layout;
  const Geometry& g = setup.scan.geometry;
  const std::size_t views = g.n_views();
  const std::size_t elements = setup.elements_per_view;
  Array out(g.is_3d() ? std::vector<std::size_t>{views, g.n_v, g.n_u}
                      : std::vector<std::size_t>{views, elements});
  for (std::size_t v = 0; v < views; ++v) {
    for (std::size_t e = 0; e < elements; ++e) {
      const float a = std::max(p[l.alpha_offset + map.slot(e, v)], 1e-8f);
      out.data[v * elements + e] = a * corrected.data[e] / trained.data[e];
    }
  }
  // The views a changing element read nothing in (after it died): 0, as simulate's alpha.
  for (const model::ResponseChange& c : setup.response_changes) {
    for (const model::ResponseMap::Segment& s : map.segments(c.element)) {
      if (!slot_unread(setup, s.slot, s.views)) continue;
      for (std::size_t v = s.first_view; v < s.first_view + s.views; ++v) {
        out.data[v * elements + c.element] = 0.0f;
      }
    }
  }
  return out;
}

}  // namespace

ReconstructionResult Reconstructor::evaluate_result() const {
  ReconstructionResult r;
  r.field_image = field_image();
  r.image = r.field_image;
  const std::vector<float> p = impl_->trainer->parameters();
  r.alpha = alpha_per_element(impl_->setup, p);
  const Array trained = r.alpha;
  evaluate_rings(r);
  evaluate_residual_detail(r, p, trained);
  evaluate_rings_after_detail(r);
  const model::StoppedHull hull =
      model::find_stopped_hull(r.image, impl_->setup.scan.measurement, impl_->setup.scan.geometry,
                               impl_->setup.starved.floor);
  r.stopped_hull_voxels = hull.voxels;
  r.stopped_hull_mean = hull.mean;
  r.alpha_by_view = responses_by_view(impl_->setup, p, trained, r.alpha);
  return r;
}

void Reconstructor::evaluate_rings_after_detail(ReconstructionResult& r) const {
  const RinerConfig& c = impl_->setup.config;
  const Geometry& g = impl_->setup.scan.geometry;
  if (g.is_3d() || !r.residual_detail.applied || !c.rings.gradient_reference ||
      !c.rings.gradient_after_detail) {
    return;
  }
  static const std::vector<double> kNoObjects;
  const std::vector<double>& objects =
      r.mirror_rings ? r.mirror_rings->object_radii_mm : kNoObjects;
  RingCorrection again =
      correct_rings_from_gradient(r.image, r.alpha, g, c.rings.gradient, objects);
  r.image = again.image;
  r.alpha = again.alpha;
  // As the chain does: what training skipped stays air (the profile is drawn on whole circles).
  model::fade_into_skipped_air(impl_->setup.occupancy, r.image.shape, 0, r.image.data);
  r.gradient_after_detail_rings = std::move(again);
}

void Reconstructor::evaluate_residual_detail(ReconstructionResult& r, const std::vector<float>& p,
                                             const Array& trained) const {
  const detail::TrainingSetup& setup = impl_->setup;
  // The residual is against what training fitted: its field and its responses, per view where
  // they change.
  Array log_alpha = responses_by_view(setup, p, trained, trained);
  if (log_alpha.size() == 0) log_alpha = trained;
  for (float& a : log_alpha.data) a = std::log(a);
  const model::Occupancy& occupancy = setup.occupancy;
  const std::vector<std::uint8_t> everything;
  ResidualDetailResult d =
      return_residual_detail(std::move(r.image), r.field_image, setup.scan, log_alpha,
                             dead_elements(), occupancy.carved ? occupancy.inside : everything,
                             setup.config.residual_detail, setup.config.engine, impl_->device);
  r.image = std::move(d.image);
  r.residual_detail = std::move(d.report);
}

void Reconstructor::evaluate_rings(ReconstructionResult& r) const {
  const RinerConfig& c = impl_->setup.config;
  const Geometry& g = impl_->setup.scan.geometry;
  if (!corrects_rings(c, g)) return;
  const model::Occupancy& occupancy = impl_->setup.occupancy;
  const std::vector<std::uint8_t> everything;  // not carved: every voxel sampled
  const std::vector<std::uint8_t>& sampled = occupancy.carved ? occupancy.inside : everything;
  if (g.is_3d()) {
    r.volume_rings =
        correct_rings_per_slice(r.image, r.alpha, g, dead_elements(), c.rings, sampled);
    r.image = r.volume_rings->image;
    r.alpha = r.volume_rings->alpha;
  } else {
    RingChain chain =
        correct_rings_in_order(r.image, r.alpha, g, dead_elements(), c.rings, sampled);
    r.image = std::move(chain.image);
    r.alpha = std::move(chain.alpha);
    r.air_rings = std::move(chain.air);
    r.gradient_rings = std::move(chain.gradient);
    r.response_rings = std::move(chain.response);
    r.gradient_after_response_rings = std::move(chain.gradient_after_response);
    r.mirror_rings = std::move(chain.mirror);
  }
}

Array Reconstructor::alpha_by_view() const { return result().alpha_by_view; }

std::vector<ChangingElement> Reconstructor::changing_elements() const {
  if (!impl_->setup.responses.varies()) return {};
  return changing_elements_of(impl_->setup, impl_->trainer->parameters());
}

Array Reconstructor::image() const { return result().image; }

Array Reconstructor::alpha() const {
  const RinerConfig& c = impl_->setup.config;
  // Without the corrections, alpha needs no evaluation of the field.
  Array alpha = corrects_rings(c, impl_->setup.scan.geometry) ? result().alpha : trained_alpha();
  Array no_beta;  // mark_dead_elements leaves an empty one alone
  mark_dead_elements(dead_elements(), alpha, no_beta);
  return alpha;
}

Array Reconstructor::trained_alpha() const {
  return alpha_per_element(impl_->setup, impl_->trainer->parameters());
}

Array Reconstructor::beta() const {
  Array no_alpha;  // mark_dead_elements leaves an empty one alone
  Array beta = trained_beta();
  mark_dead_elements(dead_elements(), no_alpha, beta);
  return beta;
}

Array Reconstructor::trained_beta() const {
  const model::ParameterLayout& l = impl_->setup.layout;
  const std::vector<float> p = impl_->trainer->parameters();
  const Geometry& g = impl_->setup.scan.geometry;
  Array out(g.is_3d() ? std::vector<std::size_t>{g.n_v, g.n_u} : std::vector<std::size_t>{g.n_u});
  for (std::size_t slot = 0; slot < l.elements; ++slot) {
    const std::size_t e = impl_->setup.responses.element_of(slot);
    const float b = 1.0f / (1.0f + std::exp(-p[l.beta_offset + slot]));
    out.data[e] = slot == e ? b : std::max(out.data[e], b);
  }
  return out;
}

std::vector<DeadElement> Reconstructor::dead_element_report() const {
  const Array b = trained_beta();
  // Per element (the slots of a changing element summed).
  std::vector<std::uint32_t> invalid(b.size(), 0);
  for (std::size_t slot = 0; slot < impl_->setup.invalid_readings.size(); ++slot) {
    invalid[impl_->setup.responses.element_of(slot)] += impl_->setup.invalid_readings[slot];
  }
  const std::size_t views = impl_->setup.scan.geometry.n_views();
  std::vector<DeadElement> dead;
  const std::vector<std::uint8_t>& stuck = impl_->setup.stuck;
  for (std::size_t e = 0; e < b.size(); ++e) {
    const bool no_reading = invalid[e] == views;
    if (!no_reading && !(b.data[e] < kDeadBelowBeta)) continue;
    const char* reason = stuck[e]     ? "stuck: steady while its neighbours vary"
                         : no_reading ? "no finite reading"
                                      : "beta below 0.5";
    dead.push_back({e, b.data[e], stuck[e] ? 0 : invalid[e], reason});
  }
  return dead;
}

std::vector<std::size_t> Reconstructor::dead_elements() const {
  std::vector<std::size_t> indices;
  for (const DeadElement& d : dead_element_report()) indices.push_back(d.element);
  return indices;
}

std::vector<LossRecord> Reconstructor::history() const {
  impl_->drain();
  return impl_->history;
}

namespace {

RayCoverage ray_coverage(std::vector<std::uint32_t> rays) {
  RayCoverage c;
  for (std::uint32_t n : rays) {
    c.rays += n;
    c.elements_under_10 += n < 10;
  }
  std::sort(rays.begin(), rays.end());
  c.fewest = rays.front();
  c.median = rays[rays.size() / 2];
  c.most = rays.back();
  return c;
}

}  // namespace

TrainingStats Reconstructor::stats() const {
  TrainingStats s;
  s.steps = impl_->steps;
  s.resumed_at_step = impl_->resumed_at;
  s.seconds = impl_->seconds;
  s.samples = impl_->samples;
  s.non_finite = impl_->setup.scan.non_finite;
  s.starved_readings = impl_->setup.starved.count;
  s.starved_floor = impl_->setup.starved.floor;
  s.filled_rows = impl_->setup.filled_rows;
  s.field_per_mu = impl_->setup.field_per_mu;
  s.typical_mu = impl_->setup.typical_mu;
  s.parameters = impl_->setup.layout.total;
  s.engine = engine_name(impl_->setup.config.engine);
  s.device = impl_->trainer->device_name();
  s.steps_planned = impl_->setup.config.training.steps;
  s.rays_per_step = impl_->setup.config.training.rays_per_step;
  s.draws_per_ray_planned = static_cast<double>(s.steps_planned) * s.rays_per_step /
                            static_cast<double>(impl_->setup.segments.size());
  s.samples_per_voxel_planned = static_cast<double>(s.steps_planned) * s.rays_per_step *
                                impl_->setup.voxel_samples_per_ray;
  s.stopped_on_plateau = impl_->plateaued;
  s.plan = impl_->trainer->plan();
  s.warm_start = impl_->warm_start;
  const detail::TrainingSetup& setup = impl_->setup;
  s.air_skipped = setup.occupancy.carved;
  s.inside_fraction = setup.occupancy.inside_fraction;
  s.samples_kept_fraction =
      setup.samples_in_grid > 0.0 ? setup.samples_kept / setup.samples_in_grid : 1.0;
  s.noise = setup.occupancy.noise;
  s.air_note = setup.occupancy.note;
  s.air_outlier_views = setup.occupancy.outlier_views;
  s.air_fbp_bin = setup.occupancy.fbp_bin;
  s.air_fbp_noise = setup.occupancy.fbp_noise;
  s.air_kept_by_fbp = setup.occupancy.kept_by_fbp;
  s.skipped_rays = setup.occupancy.skipped_rays;
  s.skipped_ray_excess = setup.occupancy.skipped_ray_excess;
  s.skipped_ray_sigmas = setup.occupancy.skipped_ray_sigmas;
  s.skipped_ray_threshold = setup.occupancy.ray_check_threshold;
  s.skipped_rays_above = setup.occupancy.skipped_rays_above;
  s.skipped_rays_near = setup.occupancy.skipped_rays_near;
  s.alpha_rate = setup.alpha_rate;
  s.stripe_rms = setup.stripe_rms;
  s.alpha_model = setup.alpha_model;
  if (setup.factor_evidence.pixels > 0) s.alpha_factor_explained = setup.factor_evidence.explained;
  s.level_warmup_steps = setup.config.training.level_warmup_steps;
  s.relative_noise = setup.noise.relative;
  s.tail_average_steps = setup.tail_average.steps;
  s.tail_average_snapshots = setup.tail_average.snapshots(impl_->steps);
  s.lr_decay_smooth = setup.config.training.lr_decay_smooth;
  s.voxels_per_ray = setup.voxels_per_ray;
  rusage usage{};
  if (getrusage(RUSAGE_SELF, &usage) == 0) {
    s.peak_host_bytes = static_cast<std::size_t>(usage.ru_maxrss) * 1024;  // kB on Linux
  }
  s.peak_device_bytes = cl::peak_buffer_bytes();
  s.coverage = ray_coverage(impl_->element_rays);
  return s;
}

const RinerConfig& Reconstructor::config() const { return impl_->setup.config; }
const Scan& Reconstructor::scan() const { return impl_->setup.scan; }

void mark_dead_elements(const std::vector<std::size_t>& dead, Array& alpha, Array& beta) {
  for (const std::size_t e : dead) {
    if (e < alpha.size()) alpha.data[e] = 0.0f;
    if (e < beta.size() && !(beta.data[e] < Reconstructor::kDeadBelowBeta)) beta.data[e] = 0.0f;
  }
}

}  // namespace riner
