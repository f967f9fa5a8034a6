#include "model_form.hpp"

#include <cmath>
#include <stdexcept>

#include "exit_status.hpp"
#include "pliant/core/deformability.hpp"

namespace pliant::cli {
namespace {

// The whole of `text` as a number, or false.
bool parse_number(const std::string& text, double& value) {
  std::size_t used = 0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    return false;
  }
  return used == text.size();
}

int steps_per_frame_of(const std::string& text) {
  double steps = 0;
  if (!parse_number(text, steps) || steps != std::floor(steps) || steps < 1 || steps > max_steps_per_frame) {
    throw UsageError("--steps-per-frame must be 'auto' or a whole number in 1.." + std::to_string(max_steps_per_frame) +
                     ", not '" + text + "'");
  }
  return static_cast<int>(steps);
}

double cluster_radius_of(const std::string& text) {
  double radius = 0;
  if (!parse_number(text, radius) || !(radius >= 1.0 && radius <= 4.0)) {
    throw UsageError("--cluster-radius must be 'auto' or a number in [1, 4], not '" + text + "'");
  }
  return radius;
}

}  // namespace

ModelFormChoice model_form_choice(const ModelFormText& text) {
  ModelFormChoice choice;
  // The parser keeps these two apart on the command line; a Python call can pass both.
  if (text.alpha && text.msm_alpha) throw UsageError("--msm-alpha excludes --alpha");
  try {
    host::parse_alpha_choice(text.alpha.value_or("auto"), choice.alpha, choice.msm_alpha);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  if (text.msm_alpha) {
    if (!(*text.msm_alpha > 0.0 && *text.msm_alpha <= 1.0)) throw UsageError("--msm-alpha must be in (0, 1]");
    choice.alpha = host::AlphaMode::fixed;
    choice.msm_alpha = *text.msm_alpha;
  }
  if (text.steps_per_frame && *text.steps_per_frame != "auto") {
    choice.steps_per_frame = steps_per_frame_of(*text.steps_per_frame);
  }
  if (text.cluster_radius && *text.cluster_radius != "auto") {
    choice.cluster_radius_auto = false;
    choice.cluster_radius_factor = cluster_radius_of(*text.cluster_radius);
  }
  return choice;
}

}  // namespace pliant::cli
