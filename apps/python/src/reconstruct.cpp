// reconstruct(): Riner on a scan from Python. Training runs with the GIL released; every
// `check_every` steps it takes the GIL back to look for Ctrl-C (the KeyboardInterrupt is raised
// once training has stopped cleanly) and to call the progress callback, which may return False
// to stop early or raise to abort.
#include <pybind11/stl.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "bindings.hpp"
#include "numpy_arrays.hpp"
#include "python_wording.hpp"
#include "riner/error.hpp"
#include "riner/geometry_doubts.hpp"
#include "riner/io.hpp"
#include "riner/reconstructor.hpp"
#include "summary_json.hpp"

namespace riner::python {

namespace {

RinerConfig config_from(const std::string& config_json,
                        const std::vector<std::pair<std::string, std::string>>& settings,
                        const std::string& engine) {
  RinerConfig config;
  if (!config_json.empty()) config.update_from_json(config_json, "config");
  for (const auto& [name, value] : settings) config.set(name, value);
  config.engine = parse_engine(engine);
  config.validate();
  return config;
}

// Calls the user's callback every `every` steps (and at the end) and watches for Ctrl-C; the
// first Python error it meets stops training and is kept to be raised afterwards.
class ProgressRelay {
 public:
  ProgressRelay(py::object callback, int every)
      : callback_(std::move(callback)), every_(every), next_report_(every) {}

  bool operator()(const TrainingProgress& p) {
    py::gil_scoped_acquire acquire;
    if (PyErr_CheckSignals() != 0) {
      failure_.emplace();
      return false;
    }
    if (callback_.is_none() || (p.step < next_report_ && p.step < p.total)) return true;
    next_report_ = (p.step / every_ + 1) * every_;
    try {
      py::dict progress;
      progress["step"] = p.step;
      progress["total"] = p.total;
      progress["loss"] = p.loss;
      progress["seconds"] = p.seconds;
      const py::object keep_going = callback_(progress);
      return keep_going.is_none() || keep_going.cast<bool>();
    } catch (py::error_already_set& e) {
      failure_.emplace(std::move(e));
      return false;
    }
  }

  // Raises what stopped training, if anything did (call with the GIL held).
  void raise_failure() {
    if (failure_) throw std::move(*failure_);
  }

 private:
  py::object callback_;
  int every_;
  int next_report_;
  std::optional<py::error_already_set> failure_;
};

py::tuple reconstruct(const py::handle& measurement, const std::string& geometry_json,
                      const std::string& config_json,
                      const std::vector<std::pair<std::string, std::string>>& settings,
                      const std::string& engine, const std::string& device,
                      const py::object& progress, int progress_every, bool quality,
                      const std::string& checkpoint, double checkpoint_minutes) {
  if (progress_every < 1) throw InputError("progress_every must be >= 1");
  if (!(checkpoint_minutes > 0.0) || !std::isfinite(checkpoint_minutes)) {
    throw InputError("checkpoint_minutes must be a number above 0");
  }
  Scan scan = scan_from(measurement, geometry_json);
  const RinerConfig config = config_from(config_json, settings, engine);
  app::require_training(config);
  // The CLI's checks of the geometry against the scan's readings (its range, a fan's distances,
  // the axis), said as Python warnings and kept in the summary.
  std::optional<CentreEstimate> centre_check;
  std::string centre_note;
  std::vector<std::string> doubts;
  {
    py::gil_scoped_release release;
    doubts = geometry_doubts(scan);
    centre_check = app::check_geometry_centre(scan, centre_note);
  }
  std::vector<std::string> warnings = doubts;
  if (!centre_note.empty()) warnings.push_back(centre_note);
  for (const std::string& warning : warnings) {
    const std::string text = python_wording(warning);
    if (PyErr_WarnEx(PyExc_UserWarning, text.c_str(), 1) < 0) throw py::error_already_set();
  }

  std::unique_ptr<Reconstructor> reconstructor;
  std::optional<Device> dev;
  {
    py::gil_scoped_release release;
    if (quality) app::require_quality_grid(scan.geometry);
    app::require_memory(scan.geometry);
    dev = device_for(config.engine, device);
    reconstructor = std::make_unique<Reconstructor>(std::move(scan), config, dev);
    if (!checkpoint.empty()) {
      // What a SIGKILL in the middle of saving left beside the checkpoint, as the CLI's --resume.
      const std::filesystem::path folder = std::filesystem::path(checkpoint).parent_path();
      remove_stale_temporaries(folder.empty() ? "." : folder);
      if (std::filesystem::exists(checkpoint)) reconstructor->resume_from(checkpoint);
    }
  }
  // Often enough for Ctrl-C to feel immediate on a CPU (50 steps: about 0.1 s), rarely enough
  // not to stall a GPU (each check drains the queue).
  constexpr int kCheckEvery = 50;
  ProgressRelay relay(progress, progress_every);
  // No file named: no checkpoint (seconds 0).
  CheckpointSaver saver(*reconstructor, checkpoint,
                        checkpoint.empty() ? 0.0 : 60.0 * checkpoint_minutes);
  {
    py::gil_scoped_release release;
    reconstructor->run(
        [&](const TrainingProgress& p) {
          // Stopped (Ctrl-C, the callback's False or its exception): saved there too.
          const bool go_on = relay(p);
          saver.after_report(p, !go_on);
          return go_on;
        },
        std::min(kCheckEvery, progress_every));
  }
  relay.raise_failure();

  ReconstructionResult result;
  std::string summary;
  Array beta;
  {
    py::gil_scoped_release release;
    result = reconstructor->result();
    beta = reconstructor->beta();
    mark_dead_elements(reconstructor->dead_elements(), result.alpha, beta);
    const app::QualityCheck check =
        quality ? app::check_quality(*reconstructor, result, dev) : app::QualityCheck{};
    nlohmann::json json = app::run_summary(*reconstructor, result, check);
    if (!quality) json["quality"] = nullptr;
    json["centre_check"] = centre_check ? app::centre_json(*centre_check) : nlohmann::json(nullptr);
    json["geometry_doubts"] = doubts;
    summary = python_wording(json.dump());
  }
  const TrainingStats done = reconstructor->stats();
  if (!checkpoint.empty() && (done.steps >= done.steps_planned || done.stopped_on_plateau)) {
    saver.discard();  // training is done: the result stands for the checkpoint
  }
  py::object alpha_by_view = py::none();
  if (result.alpha_by_view.size() > 0) alpha_by_view = to_numpy(std::move(result.alpha_by_view));
  return py::make_tuple(to_numpy(std::move(result.image)), to_numpy(std::move(result.alpha)),
                        to_numpy(std::move(beta)), summary, to_numpy(std::move(result.field_image)),
                        alpha_by_view);
}

}  // namespace

void bind_reconstruct(py::module_& m) { m.def("reconstruct", &reconstruct); }

}  // namespace riner::python
