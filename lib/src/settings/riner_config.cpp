#include "riner/riner_config.hpp"

#include <algorithm>
#include <nlohmann/json.hpp>

#include "riner/error.hpp"
#include "settings/config_settings.hpp"
#include "util/user_json.hpp"

namespace riner {

namespace {

using nlohmann::json;
using nlohmann::ordered_json;

void require(bool ok, const std::string& message) {
  if (!ok) throw InputError("config: " + message);
}

// value (already of the setting's type) against its range, before it is stored: an integer
// outside its member's range would otherwise wrap.
void check_value(const settings::Setting<RinerConfig>& s, const json& value) {
  const std::string mismatch = settings::type_mismatch(s.type, s.choices, value);
  require(mismatch.empty(), s.name() + " " + mismatch);
  if (s.type == settings::Type::kInteger || s.type == settings::Type::kNumber) {
    const std::string problem = settings::out_of_range(s, value.get<double>());
    require(problem.empty(), problem);
  }
}

const settings::Setting<RinerConfig>* find_setting(const std::string& section,
                                                   const std::string& key) {
  for (const auto& s : config_settings()) {
    if (s.section == section && s.key == key) return &s;
  }
  return nullptr;
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

const char* alpha_model_name(AlphaModel m) {
  switch (m) {
    case AlphaModel::kAuto:
      return "auto";
    case AlphaModel::kPerElement:
      return "per-element";
    case AlphaModel::kRowsTimesColumns:
      return "rows-x-columns";
  }
  return "unknown";
}

const char* air_fbp_check_name(AirFbpCheck c) {
  switch (c) {
    case AirFbpCheck::kAuto:
      return "auto";
    case AirFbpCheck::kOn:
      return "on";
    case AirFbpCheck::kOff:
      return "off";
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
    case Sampler::kEven:
      return "even";
  }
  return "unknown";
}

void RinerConfig::validate() const {
  const std::string problem = settings::first_violation(*this, config_settings());
  require(problem.empty(), problem);
  // What one setting's range cannot say.
  require(encoding.finest_resolution == 0 || encoding.finest_resolution >= encoding.base_resolution,
          "encoding.finest_resolution must be 0 (the grid's size) or >= base_resolution");
  require(encoding.log2_table_size == 0 || encoding.log2_table_size >= 4,
          "encoding.log2_table_size must be 0 (the scan's) or >= 4");
  require(network.width % 16 == 0, "network.width must be a multiple of 16");
  const TrainingConfig& t = training;
  require(t.ring_lambda == 0.0 || (draws_block(t.sampler) && t.elements_per_step >= 3),
          "training.ring_lambda needs the views-x-elements or mixed sampler with elements_per_step "
          ">= 3");
}

void RinerConfig::update_from_json(std::string_view text, std::string_view source) {
  const json root = util::parse_user_json(text, std::string(source));
  try {
    require(root.is_object(), "the settings must be a JSON object");
    const std::vector<std::string> sections = config_sections();
    for (const auto& [name, value] : root.items()) {
      const bool is_section =
          !name.empty() && std::find(sections.begin(), sections.end(), name) != sections.end();
      if (!is_section) {
        const auto* s = find_setting("", name);
        require(s != nullptr, "unknown setting " + name);
        check_value(*s, value);
        s->set(*this, value);
        continue;
      }
      require(value.is_object(), name + " must be an object");
      for (const auto& [key, v] : value.items()) {
        const auto* s = find_setting(name, key);
        require(s != nullptr, "unknown setting " + name + "." + key);
        check_value(*s, v);
        s->set(*this, v);
      }
    }
    validate();
  } catch (const json::exception& e) {
    throw InputError(std::string(source) + ": " + e.what());
  } catch (const InputError& e) {
    // The source names the settings already: "config: config: ..." said it twice.
    std::string what = e.what();
    if (what.rfind("config: ", 0) == 0) what.erase(0, 8);
    throw InputError(std::string(source) + ": " + what);
  }
}

void RinerConfig::set(std::string_view name, std::string_view value) {
  const std::string full(name);
  const auto dot = full.find('.');
  const std::string section = dot == std::string::npos ? "" : full.substr(0, dot);
  const std::string key = dot == std::string::npos ? full : full.substr(dot + 1);
  const auto* s = find_setting(section, key);
  require(s != nullptr, "unknown setting " + full + " (riner settings lists them)");
  json parsed = json::parse(value, nullptr, /*allow_exceptions=*/false);
  // A named choice may be written without quotes.
  if (parsed.is_discarded() || (s->type == settings::Type::kChoice && !parsed.is_string())) {
    parsed = std::string(value);
  }
  check_value(*s, parsed);
  RinerConfig changed = *this;
  s->set(changed, parsed);
  changed.validate();
  *this = changed;
}

std::string RinerConfig::to_json() const {
  ordered_json root = ordered_json::object();
  for (const auto& s : config_settings()) {
    const ordered_json value = ordered_json::parse(s.get(*this).dump());
    if (s.section.empty()) {
      root[s.key] = value;
    } else {
      root[s.section][s.key] = value;
    }
  }
  return root.dump(1) + "\n";
}

std::vector<RinerConfig::SettingInfo> RinerConfig::settings() {
  static const char* const kTypeNames[] = {"bool", "integer", "number", "choice"};
  const RinerConfig defaults;
  std::vector<SettingInfo> out;
  for (const auto& s : config_settings()) {
    out.push_back({s.name(), kTypeNames[static_cast<int>(s.type)], settings::allowed(s),
                   s.get(defaults).dump(), s.help});
  }
  return out;
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
  c.training.lr_decay_smooth = false;
  c.training.adam_beta1 = 0.9;
  c.training.adam_beta2 = 0.999;
  c.training.adam_epsilon = 1e-8;
  c.training.data_term = DataTerm::kSum;
  c.training.data_weight = 1.0;
  c.training.alpha_lr_scale = 1.0;
  c.training.alpha_stripe_scale = 0.0;  // the paper's alpha learns at the field's rate
  c.training.alpha_warmup_steps = 0;    // and from the first step
  c.training.beta_lr_scale = 1.0;
  c.training.unread_beta0 = 1.0;  // every element starts at beta0 = 1
  c.training.level_warmup_steps = 0;
  c.training.tail_average_steps = 0;  // the paper's result is the last step's
  c.training.stuck_elements = false;
  c.training.partial_responses = false;
  c.training.alpha_model = AlphaModel::kPerElement;
  c.training.skip_air = false;  // riner's additions, not the paper's
  c.rings.air_reference = false;
  c.rings.gradient_reference = false;
  c.rings.response_reference = false;
  c.rings.mirror_reference = false;
  c.residual_detail.enabled = false;
  return c;
}

}  // namespace riner
