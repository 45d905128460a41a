// The reference engine: the whole step in double on the CPU (reference/riner_step_ref.cpp).
#include "reference/adam_ref.hpp"
#include "riner/error.hpp"
#include "reference/alpha_factors_ref.hpp"
#include "reference/riner_step_ref.hpp"
#include "training/trainer.hpp"

namespace riner::detail {

namespace {

class ReferenceTrainer final : public Trainer {
 public:
  explicit ReferenceTrainer(const TrainingSetup& setup) : setup_(setup) {
    const std::vector<float> init = setup.initial_parameters();
    params_.assign(init.begin(), init.end());
    m_.assign(params_.size(), 0.0);
    v_.assign(params_.size(), 0.0);
    if (setup.tail_average.steps > 0) tail_sum_.assign(params_.size(), 0.0);
    inputs_.layout = &setup_.layout;
    inputs_.segments = &setup_.segments;
    inputs_.measurement = &setup_.scan.measurement.data;
    inputs_.starved_floor = setup_.starved.floor;
    inputs_.elements_per_view = setup_.elements_per_view;
    inputs_.jitter = setup_.config.training.jitter;
    inputs_.seed = setup_.seed;
    inputs_.lambda = setup_.config.training.lambda;
    inputs_.ring_lambda = setup_.config.training.ring_lambda;
    inputs_.relative_beta_threshold = setup_.config.training.relative_beta_threshold;
    inputs_.data_weight = setup_.config.training.data_weight;
    inputs_.invalid_readings = &setup_.invalid_readings;
    inputs_.responses = setup_.responses.varies() ? &setup_.responses : nullptr;
    hold_ = setup.broad_even_hold(
        std::span<const float>(init).subspan(setup.layout.alpha_offset, setup.scan.geometry.n_u));
  }

  void step(int index, const model::Batch& batch) override {
    inputs_.step = static_cast<std::uint32_t>(index);
    inputs_.level_weights = setup_.level_weights(index);
    inputs_.hold_valid_beta = setup_.hold_valid_beta(index);
    ref::StepResult r = ref::riner_step(inputs_, batch, params_);
    if (setup_.layout.factored_alpha()) ref::alpha_factors_gradient(setup_.layout, params_, r.grad);
    const model::AdamSettings adam = setup_.adam_settings(index);
    ref::adam_step(adam, index + 1, r.grad, params_, m_, v_);
    if (setup_.layout.factored_alpha()) ref::alpha_factors_expand(setup_.layout, params_);
    if (hold_ && setup_.holds_broad_even_alpha(index)) hold_broad_even_alpha();
    if (setup_.tail_average.takes(index)) {
      for (std::size_t i = 0; i < params_.size(); ++i) tail_sum_[i] += params_[i];
    }
    losses_.push_back({index, r.data_loss, r.penalty, adam.learning_rate});
    steps_ = index + 1;
  }

  std::vector<LossRecord> drain_losses() override {
    std::vector<LossRecord> out;
    out.swap(losses_);
    return out;
  }

  std::vector<float> parameters() override {
    const std::vector<double> p = result_parameters();
    return {p.begin(), p.end()};
  }

  std::vector<float> evaluate_grid() override {
    return ref::riner_step_field_evaluate(setup_.layout, result_parameters(),
                                          model::voxel_positions(setup_.scan.geometry),
                                          setup_.level_weights(steps_));
  }

  std::string device_name() const override { return "CPU reference"; }
  std::optional<ExecutionPlan> plan() const override { return std::nullopt; }

  void save_state(ByteWriter& out) override {
    for (const std::vector<double>* v : {&params_, &m_, &v_, &tail_sum_}) {
      out.put_array(std::span<const double>(*v));
    }
  }

  void restore_state(ByteReader& in, int steps) override {
    // Every part read and checked before any is taken: a refused state leaves the trainer as
    // it was.
    std::vector<std::vector<double>*> parts = {&params_, &m_, &v_, &tail_sum_};
    std::vector<std::vector<double>> values;
    for (std::vector<double>* part : parts) {
      values.push_back(in.get_array<double>());
      if (values.back().size() != part->size()) {
        throw InputError("training state: not this model's parameters");
      }
    }
    for (std::size_t i = 0; i < parts.size(); ++i) *parts[i] = std::move(values[i]);
    losses_.clear();
    steps_ = steps;
  }

 private:
  void hold_broad_even_alpha() {
    hold_->apply(std::span<double>(params_).subspan(setup_.layout.alpha_offset,
                                                    setup_.scan.geometry.n_u));
  }

  // The parameters the result is made of (model::TailAverage::snapshots): the snapshots' mean,
  // or the last step's.
  std::vector<double> result_parameters() const {
    const int snapshots = setup_.tail_average.snapshots(steps_);
    if (snapshots == 0) return params_;
    std::vector<double> mean(tail_sum_.size());
    for (std::size_t i = 0; i < mean.size(); ++i) mean[i] = tail_sum_[i] / snapshots;
    return mean;
  }

  const TrainingSetup& setup_;
  ref::StepInputs inputs_;
  std::vector<double> params_;
  std::vector<double> m_;
  std::vector<double> v_;
  std::vector<LossRecord> losses_;
  std::vector<double> tail_sum_;  // tail averaging (model/tail_average.hpp)
  std::optional<model::BroadEvenHold> hold_;  // training.alpha_warmup_broad_px
  int steps_ = 0;
};

}  // namespace

std::unique_ptr<Trainer> make_reference_trainer(const TrainingSetup& setup) {
  return std::make_unique<ReferenceTrainer>(setup);
}

}  // namespace riner::detail
