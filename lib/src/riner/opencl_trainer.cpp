// The OpenCL engine: the fused step kernel over lanes of rays, Adam on the device, losses
// copied into a history buffer on the device and read back in blocks (no per-step sync).
#include <algorithm>
#include <cstdlib>
#include <cstring>

#include "cl/context.hpp"
#include "ops/adam.hpp"
#include "ops/riner_step.hpp"
#include "riner/error.hpp"
#include "riner/trainer.hpp"

namespace riner::detail {

namespace {

constexpr int kHistoryBlock = 256;  // steps between reads of the loss history

// CPUs: one lane per compute unit, each adding into its own partial gradient (no atomics,
// deterministic). Other devices: one work-item per ray and float atomics into one gradient.
// RINER_GRADIENTS=atomic|partitioned and RINER_LANES=N override (for benchmarks).
bool use_atomics(const DeviceInfo& info) {
  if (const char* env = std::getenv("RINER_GRADIENTS"); env != nullptr && *env != '\0') {
    if (std::strcmp(env, "atomic") == 0) return true;
    if (std::strcmp(env, "partitioned") == 0) return false;
    throw InputError("RINER_GRADIENTS must be atomic or partitioned");
  }
  return info.type != "CPU";
}

cl_uint partitioned_lanes(const DeviceInfo& info) {
  if (const char* env = std::getenv("RINER_LANES"); env != nullptr && *env != '\0') {
    const long n = std::strtol(env, nullptr, 10);
    if (n < 1 || n > 1024) throw InputError("RINER_LANES must be in 1..1024");
    return static_cast<cl_uint>(n);
  }
  return std::max<cl_uint>(1, info.compute_units);
}

std::vector<cl_float8> segment_table(const std::vector<model::RaySegment>& segments) {
  std::vector<cl_float8> table(segments.size());
  static_assert(sizeof(cl_float8) == sizeof(model::RaySegment));
  std::memcpy(table.data(), segments.data(), segments.size() * sizeof(cl_float8));
  return table;
}

class OpenclTrainer final : public Trainer {
 public:
  OpenclTrainer(const TrainingSetup& setup, Device device)
      : setup_(setup),
        device_(std::move(device)),
        ctx_(device_.context()),
        atomic_(use_atomics(device_.info())),
        max_batch_(model::BatchSampler(setup.scan.geometry, setup.config.training).rays_per_step()),
        lanes_(atomic_ ? static_cast<cl_uint>(max_batch_) : partitioned_lanes(device_.info())),
        gradients_(atomic_ ? 1 : lanes_),
        params_(ctx_, std::span<const float>(
                          model::initial_parameters(setup.layout, setup.config.training.seed))),
        grad_(ctx_, gradients_ * setup.layout.total),
        loss_(ctx_, 2),
        history_(ctx_, static_cast<std::size_t>(kHistoryBlock) * 2),
        segments_(ctx_, std::span<const cl_float8>(segment_table(setup.segments)),
                  CL_MEM_READ_ONLY),
        rho_(ctx_, std::span<const float>(setup.scan.measurement.data), CL_MEM_READ_ONLY),
        invalid_readings_(ctx_, std::span<const cl_uint>(setup.invalid_readings), CL_MEM_READ_ONLY),
        rays_(ctx_, max_batch_),
        offsets_(ctx_, max_batch_ + 1),
        elements_(ctx_, max_batch_),
        weights_(ctx_, max_batch_),
        level_weights_(ctx_, static_cast<std::size_t>(setup.layout.levels)),
        step_op_(ctx_, setup.layout, atomic_, max_batch_),
        adam_(ctx_, setup.layout.total, gradients_) {
    grad_.write(std::vector<float>(grad_.size(), 0.0f));
    set_level_weights(setup_.level_weights(0));
  }

  void step(int index, const model::Batch& batch) override {
    const TrainingConfig& t = setup_.config.training;
    rays_.write(batch.rays);
    offsets_host_.resize(batch.rays.size() + 1);
    offsets_host_[0] = 0;
    for (std::size_t b = 0; b < batch.rays.size(); ++b)
      offsets_host_[b + 1] = offsets_host_[b] + setup_.segments[batch.rays[b]].count;
    offsets_.write(offsets_host_);
    sample_rays_host_.resize(offsets_host_.back());
    for (std::size_t b = 0; b < batch.rays.size(); ++b) {
      std::fill(sample_rays_host_.begin() + offsets_host_[b],
                sample_rays_host_.begin() + offsets_host_[b + 1], static_cast<cl_uint>(b));
    }
    if (sample_rays_.size() < sample_rays_host_.size())
      sample_rays_ = cl::Buffer<cl_uint>(ctx_, sample_rays_host_.size() * 5 / 4 + 1);
    sample_rays_.write(sample_rays_host_);
    elements_.write(batch.elements);
    weights_.write(batch.weights);
    set_level_weights(setup_.level_weights(index));
    ops::StepArgs args{};
    args.rays = &rays_;
    args.offsets = &offsets_;
    args.sample_rays = &sample_rays_;
    args.segments = &segments_;
    args.rho = &rho_;
    args.weights = &weights_;
    args.level_weights = &level_weights_;
    args.elements = &elements_;
    args.n_batch = static_cast<cl_uint>(batch.rays.size());
    args.n_samples = offsets_host_.back();
    args.n_elements = static_cast<cl_uint>(batch.elements.size());
    args.elements_per_view = static_cast<cl_uint>(setup_.elements_per_view);
    args.seed = setup_.seed;
    args.step = static_cast<cl_uint>(index);
    args.jitter = t.jitter;
    args.lambda = static_cast<float>(t.lambda);
    args.relative_threshold = static_cast<float>(t.relative_beta_threshold);
    args.data_weight = static_cast<float>(t.data_weight);
    args.block_first = batch.block_first;
    args.block_views = batch.block_views;
    args.block_elements = batch.block_elements;
    args.ring_lambda = static_cast<float>(t.ring_lambda);
    args.hold_valid_beta = setup_.hold_valid_beta(index);
    args.invalid_readings = &invalid_readings_;
    step_op_.step(args, lanes_, params_, grad_, loss_);
    const AdamRates rates = setup_.adam_rates(index);
    adam_.step({rates.field, setup_.layout.alpha_offset, rates.alpha, setup_.layout.beta_offset,
                rates.beta, t.adam_beta1, t.adam_beta2, t.adam_epsilon},
               index + 1, params_, grad_);
    loss_.copy_to(history_, pending_.size() * 2);
    pending_.push_back({index, 0.0, 0.0, rates.field});
    steps_ = index + 1;
    if (pending_.size() == kHistoryBlock) read_history();
  }

  std::vector<LossRecord> drain_losses() override {
    read_history();
    std::vector<LossRecord> out;
    out.swap(done_);
    return out;
  }

  std::vector<float> parameters() override { return params_.read(); }

  std::vector<float> evaluate_grid() override {
    const Geometry& g = setup_.scan.geometry;
    const std::size_t n = shape_size(g.volume_shape);
    cl::Buffer<float> out(ctx_, n);
    set_level_weights(setup_.level_weights(steps_));
    const model::SamplingDomain domain = model::sampling_domain(g);
    constexpr std::size_t kChunk = std::size_t{1} << 20;
    for (std::size_t first = 0; first < n; first += kChunk) {
      step_op_.evaluate(static_cast<cl_uint>(first),
                        static_cast<cl_uint>(std::min(kChunk, n - first)), g.volume_shape,
                        static_cast<float>(g.voxel_mm), static_cast<float>(domain.extent_mm),
                        level_weights_, params_, out);
    }
    return out.read();
  }

  std::string device_name() const override { return device_.info().full_name(); }
  std::string gradient_mode() const override { return atomic_ ? "atomic" : "partitioned"; }

 private:
  // Uploads the coarse-to-fine level scales when they change.
  void set_level_weights(const std::vector<float>& weights) {
    if (weights == current_level_weights_) return;
    level_weights_.write(weights);
    current_level_weights_ = weights;
  }

  void read_history() {
    if (pending_.empty()) return;
    const std::vector<float> values = history_.read();
    for (std::size_t i = 0; i < pending_.size(); ++i) {
      LossRecord r = pending_[i];
      r.data_loss = values[2 * i];
      r.penalty = values[2 * i + 1];
      done_.push_back(r);
    }
    pending_.clear();
  }

  const TrainingSetup& setup_;
  Device device_;
  cl::Context& ctx_;
  bool atomic_;
  std::size_t max_batch_;
  cl_uint lanes_;
  std::size_t gradients_;
  cl::Buffer<float> params_;
  cl::Buffer<float> grad_;
  cl::Buffer<float> loss_;
  cl::Buffer<float> history_;
  cl::Buffer<cl_float8> segments_;
  cl::Buffer<float> rho_;
  cl::Buffer<cl_uint> invalid_readings_;
  cl::Buffer<cl_uint> rays_;
  cl::Buffer<cl_uint> offsets_;
  std::vector<cl_uint> offsets_host_;
  cl::Buffer<cl_uint> sample_rays_;
  std::vector<cl_uint> sample_rays_host_;
  cl::Buffer<cl_uint> elements_;
  cl::Buffer<float> weights_;
  cl::Buffer<float> level_weights_;
  std::vector<float> current_level_weights_;
  ops::RinerStepOp step_op_;
  ops::AdamOp adam_;
  std::vector<LossRecord> pending_;
  std::vector<LossRecord> done_;
  int steps_ = 0;
};

}  // namespace

std::unique_ptr<Trainer> make_opencl_trainer(const TrainingSetup& setup, Device device) {
  return std::make_unique<OpenclTrainer>(setup, std::move(device));
}

}  // namespace riner::detail
