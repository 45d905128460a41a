#include "training/warm_start.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "model/batch_sampler.hpp"
#include "riner/destripe.hpp"
#include "riner/error.hpp"
#include "riner/fbp.hpp"
#include "riner/log.hpp"

namespace riner::detail {

namespace {

// Pixels per step of the image fit: a pixel is one sample, where a ray is ~70 on a 256^2 slice,
// so a step of this many costs about what a training step of 160 rays costs.
constexpr int kFitPixelsPerStep = 8192;
// alpha0 the filter may set: a response outside this is a dead element's, which beta handles.
constexpr double kAlphaMin = 0.05;
constexpr double kAlphaMax = 20.0;

// The FBP of the destriped scan, and each element's offset the filter removed (rho).
struct ClassicalAnswer {
  Array image;
  Array removed;
};

ClassicalAnswer classical_answer(const TrainingSetup& setup, std::optional<Device> device) {
  DestripeOptions filter;
  filter.method = parse_destripe_method(setup.config.training.warm_start);
  filter.engine = setup.config.engine;
  filter.device = device;
  DestripeReport report;
  Scan destriped{destripe(setup.scan.measurement, setup.scan.geometry, filter, &report),
                 setup.scan.geometry, 0};
  FbpOptions fbp_options;
  fbp_options.stopped_beam_at_floor = false;  // no metal streaks in what training reads
  fbp_options.engine = setup.config.engine;
  fbp_options.device = std::move(device);
  return {fbp(destriped, fbp_options), std::move(report.removed)};
}

// The image fit as a training setup of its own: one "view" whose elements are the pixels the
// training samples, each a ray of one sample at the pixel's centre (dx 1: the ray sum is the
// field's value there) reading the FBP's value. alpha and beta are held (rates 0, beta in its
// warm-up throughout), so the loss is the field's L1 distance to the image.
TrainingSetup image_fit_setup(const TrainingSetup& setup, const Array& image,
                              std::vector<std::size_t>& pixels) {
  const Geometry& g = setup.scan.geometry;
  const std::vector<float> positions = model::voxel_positions(g);
  const std::size_t dims = g.is_3d() ? 3 : 2;
  pixels.clear();
  for (std::size_t i = 0; i < image.size(); ++i) {
    if (setup.occupancy.inside.empty() || setup.occupancy.inside[i]) pixels.push_back(i);
  }
  TrainingSetup fit;
  fit.config = setup.config;
  TrainingConfig& t = fit.config.training;
  t.steps = t.warm_start_steps;
  t.sampler = Sampler::kUniform;
  t.rays_per_step = static_cast<int>(std::min<std::size_t>(kFitPixelsPerStep, pixels.size()));
  t.jitter = false;
  t.alpha_lr_scale = 0.0;
  t.beta_lr_scale = 0.0;
  t.beta_warmup_steps = t.steps + 1;
  t.level_warmup_steps = 0;
  t.tail_average_steps = 0;
  t.lr_decay_steps = t.steps;  // one phase: no decay within the fit
  t.lr_decay_smooth = false;
  t.lambda = 0.0;
  t.relative_beta_threshold = 0.0;
  t.ring_lambda = 0.0;
  t.data_term = DataTerm::kMean;
  fit.scan.geometry.type = GeometryType::kParallel2d;
  fit.scan.geometry.n_u = pixels.size();
  fit.scan.geometry.angles = {0.0};
  fit.scan.geometry.volume_shape = g.volume_shape;
  fit.scan.geometry.voxel_mm = g.voxel_mm;
  fit.scan.measurement = Array({1, pixels.size()});
  std::vector<model::RaySegment> segments(pixels.size());
  for (std::size_t k = 0; k < pixels.size(); ++k) {
    const std::size_t i = pixels[k];
    // In the field's unit (model/field_scale.hpp): mu times field_per_mu.
    fit.scan.measurement.data[k] = std::isfinite(image.data[i])
                                       ? static_cast<float>(image.data[i] * setup.field_per_mu)
                                       : 0.0f;
    model::RaySegment& s = segments[k];
    for (std::size_t d = 0; d < 3; ++d) {
      s.start[d] = d < dims ? positions[i * dims + d] : 0.5f;
      s.step[d] = 0.0f;
    }
    s.dx = 1.0f;
    s.count = 1;
  }
  fit.segments = model::RaySegments(std::move(segments));
  fit.elements_per_view = pixels.size();
  fit.layout = model::make_layout(static_cast<int>(dims), fit.config.encoding, fit.config.network,
                                  pixels.size());
  fit.seed = setup.seed;
  fit.invalid_readings.assign(pixels.size(), 0);
  fit.responses = model::ResponseMap(pixels.size());
  fit.tail_average = {0, t.steps};
  fit.alpha_rate = 0.0;
  return fit;
}

}  // namespace

bool warm_start_applies(const TrainingConfig& training, const Geometry& g) {
  return training.warm_start != "off" && !g.is_3d();
}

bool wants_warm_start(const TrainingSetup& setup) {
  const Geometry& g = setup.scan.geometry;
  if (setup.config.training.warm_start != "off" && g.is_3d()) {
    warn("training.warm_start is for 2D scans for now: this volume starts cold");
  }
  return warm_start_applies(setup.config.training, g);
}

WarmStart warm_start(const TrainingSetup& setup, const TrainerFactory& make_trainer,
                     std::optional<Device> device) {
  const auto start = std::chrono::steady_clock::now();
  const ClassicalAnswer answer = classical_answer(setup, std::move(device));

  std::vector<std::size_t> pixels;
  const TrainingSetup fit = image_fit_setup(setup, answer.image, pixels);
  std::unique_ptr<Trainer> trainer = make_trainer(fit);
  const model::BatchSampler sampler(fit.scan.geometry, fit.config.training);
  const int steps = fit.config.training.steps;
  for (int i = 0; i < steps; ++i) trainer->step(i, sampler.batch(static_cast<std::uint32_t>(i)));
  const std::vector<LossRecord> losses = trainer->drain_losses();
  const std::vector<float> fitted = trainer->parameters();

  WarmStart out;
  out.parameters = setup.initial_parameters();
  const model::ParameterLayout& l = setup.layout;
  if (fit.layout.alpha_offset != l.alpha_offset) {
    throw Error("warm start: the image fit's field does not match the training's layout");
  }
  std::copy(fitted.begin(), fitted.begin() + static_cast<std::ptrdiff_t>(l.alpha_offset),
            out.parameters.begin());
  double log_alpha = 0.0;
  for (std::size_t slot = 0; slot < l.elements; ++slot) {
    const std::size_t e = setup.responses.element_of(slot);
    const double alpha = std::clamp(std::exp(-static_cast<double>(answer.removed.data[e])),
                                    kAlphaMin, kAlphaMax);
    out.parameters[l.alpha_offset + slot] = static_cast<float>(alpha);
    if (slot == e) log_alpha += std::abs(std::log(alpha));
  }

  WarmStartStats& s = out.stats;
  s.method = setup.config.training.warm_start;
  s.fit_steps = steps;
  s.fit_pixels = pixels.size();
  // The data term is data_weight x beta x the mean |residual| of the batch's pixels, beta
  // held at its initial sigmoid(1); the last tenth of the fit, back in 1/mm.
  const std::size_t tail = std::max<std::size_t>(1, losses.size() / 10);
  for (std::size_t i = losses.size() - tail; i < losses.size(); ++i) {
    s.fit_residual += losses[i].data_loss;
  }
  const double beta = 1.0 / (1.0 + std::exp(-1.0));
  s.fit_residual /= static_cast<double>(tail) * fit.config.training.data_weight * beta;
  s.mean_abs_log_alpha =
      log_alpha / static_cast<double>(std::max<std::size_t>(1, setup.elements_per_view));
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace riner::detail
