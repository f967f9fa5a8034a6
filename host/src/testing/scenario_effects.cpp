// Concealed effects for simulated recordings: the catalogue, the --effect argument, the
// physics each effect sets, and occlusion of observations.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <random>
#include <set>
#include <stdexcept>

#include "pliant/host/scenarios.hpp"

namespace pliant::host {
namespace {

constexpr double kFromScenario = std::numeric_limits<double>::quiet_NaN();  // default set per scenario

struct NumberSpec {
  const char* name;
  double fallback;  // kFromScenario: the scenario decides
};

struct LabelSpec {
  const char* name;
  std::vector<std::string> allowed;  // the first is the default
};

struct EffectSpec {
  const char* name;
  std::vector<NumberSpec> numbers;
  std::vector<LabelSpec> labels;
};

const std::vector<EffectSpec>& catalogue() {
  static const std::vector<EffectSpec> specs = {
      {"plasticity", {{"yield", 0.02}, {"creep", 4.0}, {"max", 0.5}}, {}},
      {"viscosity", {{"fraction", 0.5}, {"tau", 0.8}, {"damping", 0.0}}, {}},
      {"friction", {{"mu", 0.3}}, {}},
      {"gravity", {{"g", kFromScenario}, {"tilt", 0.0}}, {}},
      {"heterogeneity", {{"ratio", 0.3}, {"radius", 2.0}}, {{"region", {"inclusion", "left", "right"}}}},
      {"stiffening", {{"k", 10.0}}, {}},
  };
  return specs;
}

std::string joined(const std::vector<std::string>& names) {
  std::string text;
  for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
  return text;
}

std::vector<std::string> parameter_names(const EffectSpec& spec) {
  std::vector<std::string> names;
  for (const NumberSpec& number : spec.numbers) names.emplace_back(number.name);
  for (const LabelSpec& label : spec.labels) names.emplace_back(label.name);
  return names;
}

const EffectSpec& spec_for(const std::string& name) {
  for (const EffectSpec& spec : catalogue()) {
    if (name == spec.name) return spec;
  }
  throw std::invalid_argument("--effect: unknown effect '" + name + "' (valid: none, " + joined(effect_names()) + ")");
}

[[noreturn]] void bad_value(const std::string& effect, const std::string& what) {
  throw std::invalid_argument("--effect " + effect + ": " + what);
}

void require(bool ok, const std::string& effect, const std::string& what) {
  if (!ok) bad_value(effect, what);
}

bool read_number(const std::string& text, double& value) {
  if (text.empty()) return false;
  char* end = nullptr;
  value = std::strtod(text.c_str(), &end);
  return end == text.c_str() + text.size();
}

std::vector<double> bounding_centre(const detail::EffectGeometry& geometry) {
  const auto dim = static_cast<std::size_t>(geometry.dimension);
  std::vector<double> low(dim, HUGE_VAL);
  std::vector<double> high(dim, -HUGE_VAL);
  for (std::size_t k = 0; k < geometry.rest.size(); ++k) {
    low[k % dim] = std::min(low[k % dim], geometry.rest[k]);
    high[k % dim] = std::max(high[k % dim], geometry.rest[k]);
  }
  std::vector<double> centre(dim);
  for (std::size_t d = 0; d < dim; ++d) centre[d] = 0.5 * (low[d] + high[d]);
  return centre;
}

}  // namespace

std::vector<std::string> effect_names() {
  std::vector<std::string> names;
  for (const EffectSpec& spec : catalogue()) names.emplace_back(spec.name);
  return names;
}

std::string describe_effects() {
  std::string text;
  for (const EffectSpec& spec : catalogue()) {
    std::string parameters;
    for (const NumberSpec& number : spec.numbers) {
      char value[32];
      std::snprintf(value, sizeof value, "%g", number.fallback);
      parameters += (parameters.empty() ? "" : ",") + std::string(number.name) + "=" +
                    (std::isnan(number.fallback) ? std::string("(per scenario)") : std::string(value));
    }
    for (const LabelSpec& label : spec.labels) {
      std::string allowed;
      for (const std::string& choice : label.allowed) allowed += (allowed.empty() ? "" : "|") + choice;
      parameters += (parameters.empty() ? "" : ",") + std::string(label.name) + "=" + allowed;
    }
    text += (text.empty() ? "" : "; ") + std::string(spec.name) + ":" + parameters;
  }
  return text;
}

void parse_effect_argument(const std::string& text, ScenarioOptions& options) {
  const std::size_t colon = text.find(':');
  const std::string name = text.substr(0, colon);
  if (name.empty()) throw std::invalid_argument("--effect: expected NAME or NAME:param=value,... (got '" + text + "')");
  options.effect = name;
  options.effect_parameters.clear();
  options.effect_labels.clear();
  if (colon == std::string::npos) return;
  std::set<std::string> seen;
  std::size_t begin = colon + 1;
  while (true) {
    const std::size_t comma = text.find(',', begin);
    const std::string item = text.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
    const std::size_t equals = item.find('=');
    if (equals == std::string::npos || equals == 0 || equals + 1 == item.size()) {
      throw std::invalid_argument("--effect " + name + ": expected param=value, got '" + item + "'");
    }
    const std::string key = item.substr(0, equals);
    const std::string value = item.substr(equals + 1);
    if (!seen.insert(key).second) throw std::invalid_argument("--effect " + name + ": " + key + " given twice");
    double number = 0.0;
    if (read_number(value, number)) {
      options.effect_parameters[key] = number;
    } else {
      options.effect_labels[key] = value;
    }
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
}

namespace detail {

EffectPhysics resolve_effect(const ScenarioOptions& options, const EffectGeometry& geometry) {
  EffectPhysics physics;
  const auto dim = static_cast<std::size_t>(geometry.dimension);
  physics.gravity.assign(dim, 0.0);
  physics.support_normal = geometry.support_normal;
  if (options.effect.empty() || options.effect == "none") {
    if (!options.effect_parameters.empty() || !options.effect_labels.empty()) {
      throw std::invalid_argument("--effect none takes no parameters");
    }
    return physics;
  }
  const EffectSpec& spec = spec_for(options.effect);
  const std::string& name = options.effect;
  physics.name = name;
  const std::string valid = " (valid: " + joined(parameter_names(spec)) + ")";

  // Every given name must belong to the effect, as a number or as a label.
  for (const auto& [key, value] : options.effect_parameters) {
    (void)value;
    const bool number =
        std::any_of(spec.numbers.begin(), spec.numbers.end(), [&](const NumberSpec& s) { return key == s.name; });
    if (number) continue;
    const auto label =
        std::find_if(spec.labels.begin(), spec.labels.end(), [&](const LabelSpec& s) { return key == s.name; });
    if (label != spec.labels.end()) bad_value(name, key + " must be one of " + joined(label->allowed));
    bad_value(name, "unknown parameter '" + key + "'" + valid);
  }
  for (const auto& [key, value] : options.effect_labels) {
    const auto label =
        std::find_if(spec.labels.begin(), spec.labels.end(), [&](const LabelSpec& s) { return key == s.name; });
    if (label == spec.labels.end()) {
      const bool number =
          std::any_of(spec.numbers.begin(), spec.numbers.end(), [&](const NumberSpec& s) { return key == s.name; });
      if (number) bad_value(name, key + " must be a number, got '" + value + "'");
      bad_value(name, "unknown parameter '" + key + "'" + valid);
    }
    if (std::find(label->allowed.begin(), label->allowed.end(), value) == label->allowed.end()) {
      bad_value(name, key + " must be one of " + joined(label->allowed) + ", got '" + value + "'");
    }
  }
  for (const NumberSpec& number : spec.numbers) {
    const auto given = options.effect_parameters.find(number.name);
    double value = given != options.effect_parameters.end() ? given->second : number.fallback;
    if (std::isnan(number.fallback) && given == options.effect_parameters.end()) value = geometry.default_gravity;
    physics.parameters[number.name] = value;
  }
  for (const LabelSpec& label : spec.labels) {
    const auto given = options.effect_labels.find(label.name);
    physics.labels[label.name] = given != options.effect_labels.end() ? given->second : label.allowed.front();
  }
  const auto& p = physics.parameters;
  auto finite_at_least = [](double value, double low) { return std::isfinite(value) && value >= low; };

  if (name == "plasticity") {
    require(finite_at_least(p.at("yield"), 0.0), name, "yield must be >= 0");
    require(finite_at_least(p.at("creep"), 0.0), name, "creep must be >= 0 (1/s)");
    require(std::isfinite(p.at("max")) && p.at("max") > 0.0, name, "max must be > 0");
    physics.plastic_yield = p.at("yield");
    physics.plastic_creep = p.at("creep");
    physics.plastic_max = p.at("max");
  } else if (name == "viscosity") {
    require(finite_at_least(p.at("fraction"), 0.0) && p.at("fraction") < 1.0, name, "fraction must be in [0, 1)");
    require(std::isfinite(p.at("tau")) && p.at("tau") > 0.0, name, "tau must be > 0 (s)");
    require(finite_at_least(p.at("damping"), 0.0), name, "damping must be >= 0 (1/s)");
    physics.relaxation_fraction = p.at("fraction");
    physics.relaxation_time_s = p.at("tau");
    physics.velocity_damping = p.at("damping");
  } else if (name == "friction") {
    require(p.at("mu") >= 0.0, name, "mu must be >= 0 (inf = pinned)");
    physics.support_friction = p.at("mu");
    physics.details["support_normal"] = geometry.support_normal;
    physics.details["support_particles"] = geometry.fixed;
  } else if (name == "gravity") {
    require(finite_at_least(p.at("g"), 0.0), name, "g must be >= 0 (length unit / s^2)");
    require(std::isfinite(p.at("tilt")) && std::abs(p.at("tilt")) <= 90.0, name, "tilt must be in [-90, 90] degrees");
    // "Down" turned toward +x (or, when down is along x, toward +y) by the tilt.
    std::vector<double> side(dim, 0.0);
    side[std::abs(geometry.down[0]) > 0.9 ? 1 : 0] = 1.0;
    double along = 0.0;
    for (std::size_t d = 0; d < dim; ++d) along += side[d] * geometry.down[d];
    double norm = 0.0;
    for (std::size_t d = 0; d < dim; ++d) {
      side[d] -= along * geometry.down[d];
      norm += side[d] * side[d];
    }
    const double angle = p.at("tilt") * std::acos(-1.0) / 180.0;
    for (std::size_t d = 0; d < dim; ++d) {
      physics.gravity[d] =
          p.at("g") * (std::cos(angle) * geometry.down[d] + std::sin(angle) * side[d] / std::sqrt(norm));
    }
    physics.details["gravity_vector"] = physics.gravity;
  } else if (name == "heterogeneity") {
    const double ratio = p.at("ratio");
    require(std::isfinite(ratio) && ratio > 0.0, name, "ratio must be > 0");
    require(ratio * options.msm_beta <= 1.0, name, "ratio x msm_beta must be at most 1");
    require(std::isfinite(p.at("radius")) && p.at("radius") > 0.0, name, "radius must be > 0 (spacings)");
    physics.region_beta_ratio = ratio;
    const std::string region = physics.labels.at("region");
    if (region == "inclusion") {
      const std::vector<double> centre = geometry.inclusion_centre;
      const double radius = p.at("radius") * geometry.spacing;
      physics.in_region = [centre, radius](const double* point) {
        double distance2 = 0.0;
        for (std::size_t d = 0; d < centre.size(); ++d) distance2 += (point[d] - centre[d]) * (point[d] - centre[d]);
        return distance2 <= radius * radius;
      };
      physics.details["inclusion_centre"] = centre;
      physics.details["inclusion_radius"] = radius;
    } else {
      const double middle = bounding_centre(geometry)[0];
      const bool left = region == "left";
      physics.in_region = [middle, left](const double* point) { return left ? point[0] < middle : point[0] > middle; };
      physics.details["split_x"] = middle;
    }
    std::vector<int> inside;
    for (std::size_t i = 0; i * dim < geometry.rest.size(); ++i) {
      if (physics.in_region(&geometry.rest[i * dim])) inside.push_back(static_cast<int>(i));
    }
    physics.details["region_particles"] = inside;
  } else if (name == "stiffening") {
    require(finite_at_least(p.at("k"), 0.0), name, "k must be >= 0");
    physics.stiffening = p.at("k");
  }
  return physics;
}

nlohmann::json effect_size(const Recording& with, const Recording& without, double noise_std) {
  // Both runs draw the same noise, so their difference is the effect alone.
  const auto dim = static_cast<std::size_t>(with.dimension);
  double sum = 0.0;
  double largest = 0.0;
  for (std::size_t k = 0; k < with.positions.size(); k += dim) {
    double squared = 0.0;
    for (std::size_t d = 0; d < dim; ++d) {
      const double difference = with.positions[k + d] - without.positions[k + d];
      squared += difference * difference;
    }
    sum += squared;
    largest = std::max(largest, std::sqrt(squared));
  }
  const double rms = std::sqrt(sum / static_cast<double>(with.positions.size()));
  return {{"rms", rms},
          {"max", largest},
          {"rms_over_noise", noise_std > 0.0 ? nlohmann::json(rms / noise_std) : nlohmann::json(nullptr)}};
}

long occlude(Recording& recording, double fraction, std::uint64_t seed) {
  const int frames = recording.frame_count();
  const int n = recording.particle_count;
  const long total = static_cast<long>(frames) * n;
  const long target = std::lround(fraction * static_cast<double>(total));
  if (target <= 0 || frames < 2) return 0;
  // A (particle, frame) pair may go missing unless it is in frame 0 or a driven particle is
  // being driven then (the tool's contact is what the recording declares as known).
  std::vector<std::uint8_t> allowed(static_cast<std::size_t>(total), 1);
  for (int i = 0; i < n; ++i) allowed[static_cast<std::size_t>(i)] = 0;
  for (const DrivenWindow& window : recording.driven) {
    for (int k = 0; k < frames; ++k) {
      const double t = recording.frame_times_s[static_cast<std::size_t>(k)];
      if (t >= window.from_s && t <= window.to_s)
        allowed[static_cast<std::size_t>(k) * static_cast<std::size_t>(n) + static_cast<std::size_t>(window.id)] = 0;
    }
  }
  const long available = std::count(allowed.begin(), allowed.end(), std::uint8_t{1});
  if (available < target) throw std::invalid_argument("--occlusion: too large for this recording");

  // Its own stream, so that the noise does not change with the occlusion.
  std::mt19937_64 rng(seed ^ 0x6f63636c7573696fULL);
  std::uniform_int_distribution<int> pick_particle(0, n - 1);
  std::uniform_int_distribution<int> pick_frame(1, frames - 1);
  std::uniform_int_distribution<int> pick_length(3, std::max(3, std::min(15, frames / 4)));
  const auto dim = static_cast<std::size_t>(recording.dimension);
  long removed = 0;
  while (removed < target) {
    const int id = pick_particle(rng);
    const int start = pick_frame(rng);
    const int length = pick_length(rng);
    for (int k = start; k < std::min(frames, start + length) && removed < target; ++k) {
      const std::size_t slot = static_cast<std::size_t>(k) * static_cast<std::size_t>(n) + static_cast<std::size_t>(id);
      if (allowed[slot] == 0) continue;
      allowed[slot] = 0;
      for (std::size_t d = 0; d < dim; ++d)
        recording.positions[slot * dim + d] = std::numeric_limits<double>::quiet_NaN();
      ++removed;
    }
  }
  return removed;
}

}  // namespace detail
}  // namespace pliant::host
