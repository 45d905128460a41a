// The OpenCL engine: the step's kernels shaped by the device's execution plan, the batch in one
// non-blocking upload per step, Adam on the device, losses written into a history buffer on
// the device and read back in blocks (no per-step sync).
#include <algorithm>
#include <cstring>

#include "cl/context.hpp"
#include "cl/device_access.hpp"
#include "cl/upload_ring.hpp"
#include "model/packed_batch.hpp"
#include "ops/adam.hpp"
#include "ops/alpha_factors.hpp"
#include "ops/riner_step.hpp"
#include "ops/vector_ops.hpp"
#include "riner/error.hpp"
#include "training/trainer.hpp"

namespace riner::detail {

namespace {

constexpr int kHistoryBlock = 256;   // steps between reads of the loss history
constexpr int kUploadsInFlight = 3;  // steps the host may prepare ahead of the device

// The setup's response table, which the step kernel indexes by every element of a view.
const std::vector<cl_uint>& response_table(const TrainingSetup& setup) {
  if (setup.responses.elements() != setup.elements_per_view) {
    throw Error("training setup: its response map does not cover the detector's elements");
  }
  return setup.responses.table();
}

class OpenclTrainer final : public Trainer {
 public:
  OpenclTrainer(const TrainingSetup& setup, Device device, const ExecutionPlan& plan)
      : setup_(setup),
        device_(std::move(device)),
        ctx_(cl::context_of(device_)),
        plan_(plan),
        params_(ctx_, std::span<const float>(setup.initial_parameters())),
        grad_(ctx_, std::vector<float>(setup.layout.total, 0.0f)),
        history_(ctx_, static_cast<std::size_t>(kHistoryBlock) * 2),
        invalid_readings_(ctx_, std::span<const cl_uint>(setup.invalid_readings), CL_MEM_READ_ONLY),
        response_slots_(ctx_, std::span<const cl_uint>(response_table(setup)), CL_MEM_READ_ONLY),
        level_weights_(ctx_, static_cast<std::size_t>(setup.layout.levels)),
        uploads_(ctx_, kUploadsInFlight),
        step_op_(ctx_, setup.layout, plan_,
                 model::BatchSampler(setup.scan.geometry, setup.config.training).rays_per_step()),
        adam_(ctx_, setup.layout.total) {
    if (setup.layout.factored_alpha()) factors_.emplace(ctx_, setup.layout);
    hold_ = setup.broad_even_hold(read_alpha());
    if (setup.tail_average.steps > 0) {
      vector_ops_.emplace(ctx_);
      tail_sum_.emplace(ctx_, std::vector<float>(setup.layout.total, 0.0f));
    }
  }

  void step(int index, const model::Batch& batch) override {
    const TrainingConfig& t = setup_.config.training;
    model::pack_batch(batch, setup_.segments, setup_.scan.measurement.data,
                      setup_.elements_per_view, setup_.level_weights(index), packed_);
    ops::StepParams p;
    ops::set_batch_shape(packed_, p);
    p.elements_per_view = static_cast<cl_uint>(setup_.elements_per_view);
    p.seed = setup_.seed;
    p.step = static_cast<cl_uint>(index);
    p.jitter = t.jitter ? 1 : 0;
    p.hold_valid_beta = setup_.hold_valid_beta(index) ? 1 : 0;
    p.history_slot = static_cast<cl_uint>(pending_.size());
    p.lambda = static_cast<float>(t.lambda);
    p.relative_beta_threshold = static_cast<float>(t.relative_beta_threshold);
    p.data_weight = static_cast<float>(t.data_weight);
    p.ring_lambda = static_cast<float>(t.ring_lambda);
    p.starved_floor = setup_.starved.floor;
    p.block_first = batch.block_first;
    p.block_views = batch.block_views;
    p.block_elements = batch.block_elements;
    const cl::Buffer<cl_uint>& words = uploads_.upload(packed_.words);
    step_op_.step(p, words, {&invalid_readings_, &response_slots_}, params_, grad_, history_);
    if (factors_) factors_->gradient(params_, grad_);
    const model::AdamSettings adam = setup_.adam_settings(index);
    adam_.step(adam, index + 1, params_, grad_,
               {&step_op_.mlp_partials(), setup_.layout.mlp_offset, setup_.layout.mlp_params,
                step_op_.mlp_slices()});
    if (factors_) factors_->expand(params_);
    if (hold_ && setup_.holds_broad_even_alpha(index)) hold_broad_even_alpha();
    if (setup_.tail_average.takes(index)) vector_ops_->axpy(1.0f, params_, *tail_sum_);
    pending_.push_back({index, 0.0, 0.0, adam.learning_rate});
    steps_ = index + 1;
    if (pending_.size() == kHistoryBlock) read_history();
  }

  std::vector<LossRecord> drain_losses() override {
    read_history();
    std::vector<LossRecord> out;
    out.swap(done_);
    return out;
  }

  std::vector<float> parameters() override { return result_parameters().read(); }

  std::vector<float> evaluate_grid() override {
    const Geometry& g = setup_.scan.geometry;
    const std::size_t n = shape_size(g.volume_shape);
    cl::Buffer<float> out(ctx_, n);
    level_weights_.write(setup_.level_weights(steps_));
    const model::SamplingDomain domain = model::sampling_domain(g);
    const cl::Buffer<float>& params = result_parameters();
    constexpr std::size_t kChunk = std::size_t{1} << 20;
    for (std::size_t first = 0; first < n; first += kChunk) {
      step_op_.evaluate(static_cast<cl_uint>(first),
                        static_cast<cl_uint>(std::min(kChunk, n - first)), g.volume_shape,
                        static_cast<float>(g.voxel_mm), static_cast<float>(domain.extent_mm),
                        level_weights_, params, out);
    }
    return out.read();
  }

  std::string device_name() const override { return device_.info().full_name(); }
  std::optional<ExecutionPlan> plan() const override { return plan_; }

  void save_state(ByteWriter& out) override {
    if (!pending_.empty()) throw Error("training state: losses not drained");
    out.put_array(std::span<const float>(params_.read()));
    out.put_array(std::span<const float>(adam_.first_moments().read()));
    out.put_array(std::span<const float>(adam_.second_moments().read()));
    out.put_array(std::span<const float>(tail_sum_ ? tail_sum_->read() : std::vector<float>()));
  }

  void restore_state(ByteReader& in, int steps) override {
    const std::vector<float> params = in.get_array<float>();
    const std::vector<float> m = in.get_array<float>();
    const std::vector<float> v = in.get_array<float>();
    const std::vector<float> tail = in.get_array<float>();
    // Every size checked before anything is written: a refused state leaves the trainer as it was.
    if (params.size() != params_.size() || m.size() != params.size() ||
        v.size() != params.size() || tail.size() != (tail_sum_ ? tail_sum_->size() : 0)) {
      throw InputError("training state: not this model's parameters");
    }
    params_.write(params);
    adam_.set_moments(m, v);
    if (tail_sum_) tail_sum_->write(tail);
    pending_.clear();
    steps_ = steps;
  }

 private:
  // The parameters the result is made of (model::TailAverage::snapshots): the snapshots' mean,
  // or the last step's.
  const cl::Buffer<float>& result_parameters() {
    const int snapshots = setup_.tail_average.snapshots(steps_);
    if (snapshots == 0) return params_;
    if (!tail_mean_) tail_mean_.emplace(ctx_, setup_.layout.total);
    vector_ops_->fill(*tail_mean_, 0.0f);
    vector_ops_->axpy(1.0f / static_cast<float>(snapshots), *tail_sum_, *tail_mean_);
    return *tail_mean_;
  }

  // alpha0 of each element (its first segment's).
  std::vector<float> read_alpha() const {
    std::vector<float> alpha(setup_.scan.geometry.n_u);
    params_.read(std::span<float>(alpha), setup_.layout.alpha_offset);
    return alpha;
  }

  // A few thousand values a step, for the hold's few hundred steps: on the host.
  void hold_broad_even_alpha() {
    std::vector<float> alpha = read_alpha();
    hold_->apply(alpha);
    params_.write(std::span<const float>(alpha), setup_.layout.alpha_offset);
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
  ExecutionPlan plan_;
  cl::Buffer<float> params_;
  cl::Buffer<float> grad_;
  cl::Buffer<float> history_;
  cl::Buffer<cl_uint> invalid_readings_;
  cl::Buffer<cl_uint> response_slots_;  // model/response_map.hpp's table
  cl::Buffer<float> level_weights_;
  cl::UploadRing<cl_uint> uploads_;
  model::PackedBatch packed_;
  ops::RinerStepOp step_op_;
  ops::AdamOp adam_;
  std::optional<ops::AlphaFactorsOp> factors_;  // alpha as row x column factors
  std::optional<ops::VectorOps> vector_ops_;    // tail averaging (model/tail_average.hpp)
  std::optional<cl::Buffer<float>> tail_sum_;
  std::optional<cl::Buffer<float>> tail_mean_;
  std::optional<model::BroadEvenHold> hold_;  // training.alpha_warmup_broad_px
  std::vector<LossRecord> pending_;
  std::vector<LossRecord> done_;
  int steps_ = 0;
};

}  // namespace

std::unique_ptr<Trainer> make_opencl_trainer(const TrainingSetup& setup, Device device,
                                             const ExecutionPlan& plan) {
  return std::make_unique<OpenclTrainer>(setup, std::move(device), plan);
}

}  // namespace riner::detail
