#include "riner/riner_config.hpp"

#include <cmath>
#include <nlohmann/json.hpp>

#include "riner/error.hpp"

namespace riner {

namespace {

using nlohmann::json;

void require(bool ok, const std::string& message) {
  if (!ok) throw InputError("config: " + message);
}

// Copies obj[key] into value when present, checking its type; unknown keys are rejected by
// the caller's key list.
template <typename T>
void read(const json& obj, const char* section, const char* key, T& value) {
  if (!obj.contains(key)) return;
  const json& v = obj.at(key);
  const std::string name = std::string(section) + "." + key;
  if constexpr (std::is_same_v<T, bool>) {
    require(v.is_boolean(), name + " must be true or false");
    value = v.get<bool>();
  } else if constexpr (std::is_integral_v<T>) {
    require(v.is_number_integer(), name + " must be an integer");
    value = v.get<T>();
  } else {
    require(v.is_number(), name + " must be a number");
    value = v.get<T>();
  }
}

void check_keys(const json& obj, const char* section, std::initializer_list<const char*> keys) {
  require(obj.is_object(), std::string(section) + " must be an object");
  for (const auto& [key, _] : obj.items()) {
    bool known = false;
    for (const char* k : keys) known = known || key == k;
    require(known, "unknown setting " + std::string(section) + "." + key);
  }
}

}  // namespace

const char* data_term_name(DataTerm t) {
  switch (t) {
    case DataTerm::kElementMean:
      return "element-mean";
    case DataTerm::kMean:
      return "mean";
    case DataTerm::kSum:
      return "sum";
  }
  return "unknown";
}

const char* sampler_name(Sampler s) {
  switch (s) {
    case Sampler::kUniform:
      return "uniform";
    case Sampler::kViewsTimesElements:
      return "views-x-elements";
    case Sampler::kMixed:
      return "mixed";
  }
  return "unknown";
}

void RinerConfig::validate() const {
  const EncodingConfig& e = encoding;
  require(e.levels >= 1 && e.levels <= 32, "encoding.levels must be in 1..32");
  require(e.features >= 1 && e.features <= 8, "encoding.features must be in 1..8");
  require(e.log2_table_size >= 4 && e.log2_table_size <= 26,
          "encoding.log2_table_size must be in 4..26");
  require(e.base_resolution >= 2 && e.base_resolution <= 65536,
          "encoding.base_resolution must be in 2..65536");
  require(
      e.finest_resolution == 0 ||
          (e.finest_resolution >= e.base_resolution && e.finest_resolution <= 1 << 20),
      "encoding.finest_resolution must be 0 (the grid's size) or >= base_resolution and <= 2^20");
  require(network.width >= 16 && network.width <= 256 && network.width % 16 == 0,
          "network.width must be a multiple of 16 in 16..256");
  require(network.hidden_layers >= 1 && network.hidden_layers <= 4,
          "network.hidden_layers must be in 1..4");
  const TrainingConfig& t = training;
  require(t.steps >= 0 && t.steps <= 10000000, "training.steps must be in 0..10^7");
  require(t.rays_per_step >= 0 && t.rays_per_step <= 1 << 20,
          "training.rays_per_step must be in 1..2^20, or 0 (the device's execution plan chooses)");
  require(t.views_per_step >= 1 && t.views_per_step <= 1 << 16,
          "training.views_per_step must be in 1..65536");
  require(t.elements_per_step >= 1 && t.elements_per_step <= 1 << 16,
          "training.elements_per_step must be in 1..65536");
  require(t.sample_spacing > 0.01 && t.sample_spacing <= 100.0,
          "training.sample_spacing must be in (0.01, 100] voxels");
  require(t.air_noise_sigmas >= 0.5 && t.air_noise_sigmas <= 100.0,
          "training.air_noise_sigmas must be in [0.5, 100]");
  require(t.air_margin_px >= 0 && t.air_margin_px <= 64, "training.air_margin_px must be in 0..64");
  require(t.learning_rate > 0.0 && t.learning_rate < 10.0 && std::isfinite(t.learning_rate),
          "training.learning_rate must be in (0, 10)");
  require(t.lr_decay_steps >= 0, "training.lr_decay_steps must be >= 0 (0: steps / 4)");
  require(t.lr_decay > 0.0 && t.lr_decay <= 1.0, "training.lr_decay must be in (0, 1]");
  require(t.adam_beta1 >= 0.0 && t.adam_beta1 < 1.0, "training.adam_beta1 must be in [0, 1)");
  require(t.adam_beta2 >= 0.0 && t.adam_beta2 < 1.0, "training.adam_beta2 must be in [0, 1)");
  require(t.adam_epsilon > 0.0 && t.adam_epsilon < 1.0, "training.adam_epsilon must be in (0, 1)");
  require(t.lambda >= 0.0 && t.lambda < 1e6 && std::isfinite(t.lambda),
          "training.lambda must be >= 0");
  require(t.alpha_lr_scale >= 0.0 && t.alpha_lr_scale < 1e3,
          "training.alpha_lr_scale must be in [0, 1000)");
  require(t.beta_lr_scale >= 0.0 && t.beta_lr_scale < 1e3,
          "training.beta_lr_scale must be in [0, 1000)");
  require(t.alpha_warmup_steps >= 0, "training.alpha_warmup_steps must be >= 0");
  require(t.beta_warmup_steps >= -1,
          "training.beta_warmup_steps must be >= 0, or -1 (the first learning-rate phase)");
  require(t.level_warmup_steps >= 0, "training.level_warmup_steps must be >= 0");
  require(t.plateau_window >= 0,
          "training.plateau_window must be >= 0 (0: a quarter of the "
          "last learning-rate phase)");
  require(t.plateau_tolerance >= 0.0 && t.plateau_tolerance < 1.0,
          "training.plateau_tolerance must be in [0, 1)");
  require(t.ring_lambda >= 0.0 && t.ring_lambda < 1e9 && std::isfinite(t.ring_lambda),
          "training.ring_lambda must be >= 0");
  require(t.ring_lambda == 0.0 || (t.sampler != Sampler::kUniform && t.elements_per_step >= 3),
          "training.ring_lambda needs the views-x-elements or mixed sampler with elements_per_step "
          ">= 3");
  require(t.relative_beta_threshold >= 0.0 && t.relative_beta_threshold < 1e6,
          "training.relative_beta_threshold must be >= 0");
  require(t.data_weight > 0.0 && t.data_weight < 1e6 && std::isfinite(t.data_weight),
          "training.data_weight must be > 0");
  require(plan.kind == "auto" || plan.kind == "cpu" || plan.kind == "gpu",
          "plan.kind must be auto, cpu or gpu");
  require(plan.float_atomics == "auto" || plan.float_atomics == "nvidia-ptx" ||
              plan.float_atomics == "cl_ext_float_atomics" || plan.float_atomics == "amd-builtin" ||
              plan.float_atomics == "compare-exchange",
          "plan.float_atomics must be auto, nvidia-ptx, cl_ext_float_atomics, amd-builtin or "
          "compare-exchange");
  require(plan.sample_group >= 0 && plan.sample_group <= 4096,
          "plan.sample_group must be in 0..4096 (0: the device's choice)");
  require(plan.gradient_slices >= 0 && plan.gradient_slices <= 65536,
          "plan.gradient_slices must be in 0..65536 (0: the device's choice)");
  require(plan.grid_bands >= 0 && plan.grid_bands <= 4096,
          "plan.grid_bands must be in 0..4096 (0: the device's choice)");
  const AirRingSettings& air = rings.air;
  require(air.air_fraction > 0.0 && air.air_fraction < 1.0, "rings.air_fraction must be in (0, 1)");
  require(air.erosion_px >= 0 && air.erosion_px <= 64, "rings.air_erosion_px must be in 0..64");
  require(air.min_pixels >= 1 && air.min_pixels <= 1 << 20,
          "rings.min_air_pixels must be in 1..2^20");
  require(air.max_mean_response_change > 0.0 && air.max_mean_response_change <= 10.0,
          "rings.max_mean_response_change must be in (0, 10]");
  require(air.smoothing_bins >= 0.0 && air.smoothing_bins <= 100.0,
          "rings.smoothing_bins must be in [0, 100]");
  const GradientRingSettings& gradient = rings.gradient;
  require(gradient.scale_px > 0.0 && gradient.scale_px <= 1000.0,
          "rings.gradient_scale_px must be in (0, 1000]");
  require(gradient.flat_fraction > 0.0 && gradient.flat_fraction <= 1.0,
          "rings.gradient_flat_fraction must be in (0, 1]");
  require(gradient.max_mean_response_change > 0.0 && gradient.max_mean_response_change <= 10.0,
          "rings.gradient_max_mean_response_change must be in (0, 10]");
  const ResponseRingSettings& response = rings.response;
  require(response.scale_px > 0.0 && response.scale_px <= 1000.0,
          "rings.response_scale_px must be in (0, 1000]");
  require(response.air_weight >= 0.0 && response.air_weight <= 1e6,
          "rings.response_air_weight must be in [0, 1e6]");
  require(response.min_even_to_odd >= 0.0 && response.min_even_to_odd <= 1e6,
          "rings.response_min_even_to_odd must be in [0, 1e6]");
  require(response.max_mean_response_change > 0.0 && response.max_mean_response_change <= 10.0,
          "rings.response_max_mean_response_change must be in (0, 10]");
}

void RinerConfig::update_from_json(std::string_view text, std::string_view source) {
  json root;
  try {
    root = json::parse(text);
  } catch (const json::exception& e) {
    throw InputError(std::string(source) + ": invalid JSON: " + e.what());
  }
  try {
    check_keys(root, "config", {"encoding", "network", "training", "rings", "engine", "plan"});
    if (root.contains("encoding")) {
      const json& e = root["encoding"];
      check_keys(e, "encoding",
                 {"levels", "features", "log2_table_size", "base_resolution", "finest_resolution"});
      read(e, "encoding", "levels", encoding.levels);
      read(e, "encoding", "features", encoding.features);
      read(e, "encoding", "log2_table_size", encoding.log2_table_size);
      read(e, "encoding", "base_resolution", encoding.base_resolution);
      read(e, "encoding", "finest_resolution", encoding.finest_resolution);
    }
    if (root.contains("network")) {
      const json& n = root["network"];
      check_keys(n, "network", {"width", "hidden_layers"});
      read(n, "network", "width", network.width);
      read(n, "network", "hidden_layers", network.hidden_layers);
    }
    if (root.contains("training")) {
      const json& t = root["training"];
      check_keys(t, "training",
                 {"steps",
                  "sampler",
                  "rays_per_step",
                  "views_per_step",
                  "elements_per_step",
                  "sample_spacing",
                  "jitter",
                  "circle_region",
                  "skip_air",
                  "air_noise_sigmas",
                  "air_margin_px",
                  "learning_rate",
                  "lr_decay_steps",
                  "lr_decay",
                  "adam_beta1",
                  "adam_beta2",
                  "adam_epsilon",
                  "lambda",
                  "alpha_lr_scale",
                  "beta_lr_scale",
                  "alpha_warmup_steps",
                  "beta_warmup_steps",
                  "level_warmup_steps",
                  "stop_on_plateau",
                  "plateau_window",
                  "plateau_tolerance",
                  "ring_lambda",
                  "data_term",
                  "data_weight",
                  "relative_beta_threshold",
                  "seed"});
      read(t, "training", "steps", training.steps);
      if (t.contains("sampler")) {
        require(t["sampler"].is_string(), "training.sampler must be a string");
        const std::string s = t["sampler"];
        bool known = false;
        for (Sampler option : {Sampler::kUniform, Sampler::kViewsTimesElements, Sampler::kMixed}) {
          if (s == sampler_name(option)) {
            training.sampler = option;
            known = true;
          }
        }
        require(known, "training.sampler must be uniform, views-x-elements or mixed");
      }
      read(t, "training", "rays_per_step", training.rays_per_step);
      read(t, "training", "views_per_step", training.views_per_step);
      read(t, "training", "elements_per_step", training.elements_per_step);
      read(t, "training", "sample_spacing", training.sample_spacing);
      read(t, "training", "jitter", training.jitter);
      read(t, "training", "circle_region", training.circle_region);
      read(t, "training", "skip_air", training.skip_air);
      read(t, "training", "air_noise_sigmas", training.air_noise_sigmas);
      read(t, "training", "air_margin_px", training.air_margin_px);
      read(t, "training", "learning_rate", training.learning_rate);
      read(t, "training", "lr_decay_steps", training.lr_decay_steps);
      read(t, "training", "lr_decay", training.lr_decay);
      read(t, "training", "adam_beta1", training.adam_beta1);
      read(t, "training", "adam_beta2", training.adam_beta2);
      read(t, "training", "adam_epsilon", training.adam_epsilon);
      read(t, "training", "lambda", training.lambda);
      if (t.contains("data_term")) {
        require(t["data_term"].is_string(), "training.data_term must be a string");
        const std::string d = t["data_term"];
        bool known = false;
        for (DataTerm term : {DataTerm::kElementMean, DataTerm::kMean, DataTerm::kSum}) {
          if (d == data_term_name(term)) {
            training.data_term = term;
            known = true;
          }
        }
        require(known, "training.data_term must be element-mean, mean or sum");
      }
      read(t, "training", "data_weight", training.data_weight);
      read(t, "training", "relative_beta_threshold", training.relative_beta_threshold);
      read(t, "training", "alpha_lr_scale", training.alpha_lr_scale);
      read(t, "training", "beta_lr_scale", training.beta_lr_scale);
      read(t, "training", "alpha_warmup_steps", training.alpha_warmup_steps);
      read(t, "training", "beta_warmup_steps", training.beta_warmup_steps);
      read(t, "training", "level_warmup_steps", training.level_warmup_steps);
      read(t, "training", "stop_on_plateau", training.stop_on_plateau);
      read(t, "training", "plateau_window", training.plateau_window);
      read(t, "training", "plateau_tolerance", training.plateau_tolerance);
      read(t, "training", "ring_lambda", training.ring_lambda);
      read(t, "training", "seed", training.seed);
    }
    if (root.contains("rings")) {
      const json& r = root["rings"];
      check_keys(
          r, "rings",
          {"air_reference", "air_fraction", "air_erosion_px", "min_air_pixels",
           "max_mean_response_change", "smoothing_bins", "gradient_reference", "gradient_scale_px",
           "gradient_flat_fraction", "gradient_max_mean_response_change", "response_reference",
           "response_scale_px", "response_air_weight", "response_min_even_to_odd",
           "response_max_mean_response_change"});
      read(r, "rings", "air_reference", rings.air_reference);
      read(r, "rings", "air_fraction", rings.air.air_fraction);
      read(r, "rings", "air_erosion_px", rings.air.erosion_px);
      read(r, "rings", "min_air_pixels", rings.air.min_pixels);
      read(r, "rings", "max_mean_response_change", rings.air.max_mean_response_change);
      read(r, "rings", "smoothing_bins", rings.air.smoothing_bins);
      read(r, "rings", "gradient_reference", rings.gradient_reference);
      read(r, "rings", "gradient_scale_px", rings.gradient.scale_px);
      read(r, "rings", "gradient_flat_fraction", rings.gradient.flat_fraction);
      read(r, "rings", "gradient_max_mean_response_change",
           rings.gradient.max_mean_response_change);
      read(r, "rings", "response_reference", rings.response_reference);
      read(r, "rings", "response_scale_px", rings.response.scale_px);
      read(r, "rings", "response_air_weight", rings.response.air_weight);
      read(r, "rings", "response_min_even_to_odd", rings.response.min_even_to_odd);
      read(r, "rings", "response_max_mean_response_change",
           rings.response.max_mean_response_change);
    }
    if (root.contains("plan")) {
      const json& p = root["plan"];
      check_keys(p, "plan",
                 {"kind", "float_atomics", "sample_group", "gradient_slices", "grid_bands"});
      for (const char* key : {"kind", "float_atomics"}) {
        if (!p.contains(key)) continue;
        require(p[key].is_string(), std::string("plan.") + key + " must be a string");
        (std::string(key) == "kind" ? plan.kind : plan.float_atomics) = p[key].get<std::string>();
      }
      read(p, "plan", "sample_group", plan.sample_group);
      read(p, "plan", "gradient_slices", plan.gradient_slices);
      read(p, "plan", "grid_bands", plan.grid_bands);
    }
    if (root.contains("engine")) {
      require(root["engine"].is_string(), "engine must be a string");
      engine = parse_engine(root["engine"].get<std::string>());
    }
  } catch (const json::exception& e) {
    throw InputError(std::string(source) + ": " + e.what());
  } catch (const InputError& e) {
    throw InputError(std::string(source) + ": " + e.what());
  }
  validate();
}

std::string RinerConfig::to_json() const {
  json root = {{"encoding",
                {{"levels", encoding.levels},
                 {"features", encoding.features},
                 {"log2_table_size", encoding.log2_table_size},
                 {"base_resolution", encoding.base_resolution},
                 {"finest_resolution", encoding.finest_resolution}}},
               {"network", {{"width", network.width}, {"hidden_layers", network.hidden_layers}}},
               {"training",
                {{"steps", training.steps},
                 {"sampler", sampler_name(training.sampler)},
                 {"rays_per_step", training.rays_per_step},
                 {"views_per_step", training.views_per_step},
                 {"elements_per_step", training.elements_per_step},
                 {"sample_spacing", training.sample_spacing},
                 {"jitter", training.jitter},
                 {"circle_region", training.circle_region},
                 {"skip_air", training.skip_air},
                 {"air_noise_sigmas", training.air_noise_sigmas},
                 {"air_margin_px", training.air_margin_px},
                 {"learning_rate", training.learning_rate},
                 {"lr_decay_steps", training.lr_decay_steps},
                 {"lr_decay", training.lr_decay},
                 {"adam_beta1", training.adam_beta1},
                 {"adam_beta2", training.adam_beta2},
                 {"adam_epsilon", training.adam_epsilon},
                 {"lambda", training.lambda},
                 {"data_term", data_term_name(training.data_term)},
                 {"data_weight", training.data_weight},
                 {"relative_beta_threshold", training.relative_beta_threshold},
                 {"alpha_lr_scale", training.alpha_lr_scale},
                 {"beta_lr_scale", training.beta_lr_scale},
                 {"alpha_warmup_steps", training.alpha_warmup_steps},
                 {"beta_warmup_steps", training.beta_warmup_steps},
                 {"level_warmup_steps", training.level_warmup_steps},
                 {"stop_on_plateau", training.stop_on_plateau},
                 {"plateau_window", training.plateau_window},
                 {"plateau_tolerance", training.plateau_tolerance},
                 {"ring_lambda", training.ring_lambda},
                 {"seed", training.seed}}},
               {"rings",
                {{"air_reference", rings.air_reference},
                 {"air_fraction", rings.air.air_fraction},
                 {"air_erosion_px", rings.air.erosion_px},
                 {"min_air_pixels", rings.air.min_pixels},
                 {"max_mean_response_change", rings.air.max_mean_response_change},
                 {"smoothing_bins", rings.air.smoothing_bins},
                 {"gradient_reference", rings.gradient_reference},
                 {"gradient_scale_px", rings.gradient.scale_px},
                 {"gradient_flat_fraction", rings.gradient.flat_fraction},
                 {"gradient_max_mean_response_change", rings.gradient.max_mean_response_change},
                 {"response_reference", rings.response_reference},
                 {"response_scale_px", rings.response.scale_px},
                 {"response_air_weight", rings.response.air_weight},
                 {"response_min_even_to_odd", rings.response.min_even_to_odd},
                 {"response_max_mean_response_change", rings.response.max_mean_response_change}}},
               {"plan",
                {{"kind", plan.kind},
                 {"float_atomics", plan.float_atomics},
                 {"sample_group", plan.sample_group},
                 {"gradient_slices", plan.gradient_slices},
                 {"grid_bands", plan.grid_bands}}},
               {"engine", engine_name(engine)}};
  return root.dump(1) + "\n";
}

RinerConfig RinerConfig::paper() {
  RinerConfig c;
  c.encoding = {10, 8, 10, 2, 1024};  // b = 2: 2 * 2^9 = 1024
  c.network = {128, 1};
  c.training.steps = 4000;
  c.training.sampler = Sampler::kViewsTimesElements;
  c.training.views_per_step = 40;
  c.training.elements_per_step = 2;
  c.training.learning_rate = 1e-3;
  c.training.lr_decay_steps = 1000;
  c.training.lr_decay = 0.5;
  c.training.adam_beta1 = 0.9;
  c.training.adam_beta2 = 0.999;
  c.training.adam_epsilon = 1e-8;
  c.training.data_term = DataTerm::kSum;
  c.training.data_weight = 1.0;
  c.training.alpha_lr_scale = 1.0;
  c.training.beta_lr_scale = 1.0;
  c.training.skip_air = false;  // riner's additions, not the paper's
  c.rings.air_reference = false;
  c.rings.gradient_reference = false;
  c.rings.response_reference = false;
  return c;
}

}  // namespace riner
