#include "model_form_options.hpp"

#include <cmath>
#include <stdexcept>

#include "exit_status.hpp"
#include "pliant/core/deformability.hpp"

namespace pliant::cli {

void ModelFormOptions::add_to(CLI::App& app) {
  auto* alpha_option =
      app.add_option("--alpha", alpha_,
                     "msm_alpha: 'auto' (default) fits it with msm_beta when the recording determines it (BIC), "
                     "'fit' (also a bare --alpha) always, 'fixed=A' holds it at A in (0, 1] (the old default A = 1)")
          ->type_name("auto|fit|fixed=A")
          ->expected(0, 1);
  app.add_option("--msm-alpha", msm_alpha_, "Same as --alpha fixed=A")->type_name("A")->excludes(alpha_option);
  app.add_option("--steps-per-frame", steps_per_frame_,
                 "MSM steps per frame interval: 'auto' (default) chooses 1-4 with msm_alpha (BIC), or N in 1..64")
      ->type_name("auto|N")
      ->capture_default_str();
  app.add_option("--cluster-radius", cluster_radius_,
                 "MSM cluster radius over the median neighbour distance: 'auto' (default) chooses among 1.3-2.25 "
                 "with the rest (BIC), or F in [1, 4]")
      ->type_name("auto|F")
      ->capture_default_str();
}

bool ModelFormOptions::given(const CLI::App& app) {
  return app.count("--alpha") + app.count("--msm-alpha") + app.count("--steps-per-frame") +
             app.count("--cluster-radius") >
         0;
}

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

}  // namespace

ModelFormChoice ModelFormOptions::apply(const CLI::App& app) const {
  ModelFormChoice choice;
  try {
    host::parse_alpha_choice(alpha_, choice.alpha, choice.msm_alpha);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
  if (app.count("--msm-alpha") > 0) {
    if (!(msm_alpha_ > 0.0 && msm_alpha_ <= 1.0)) throw UsageError("--msm-alpha must be in (0, 1]");
    choice.alpha = host::AlphaMode::fixed;
    choice.msm_alpha = msm_alpha_;
  }
  if (steps_per_frame_ != "auto") {
    double steps = 0;
    if (!parse_number(steps_per_frame_, steps) || steps != std::floor(steps) || steps < 1 ||
        steps > max_steps_per_frame) {
      throw UsageError("--steps-per-frame must be 'auto' or a whole number in 1.." +
                       std::to_string(max_steps_per_frame) + ", not '" + steps_per_frame_ + "'");
    }
    choice.steps_per_frame = static_cast<int>(steps);
  }
  if (cluster_radius_ != "auto") {
    double radius = 0;
    if (!parse_number(cluster_radius_, radius) || !(radius >= 1.0 && radius <= 4.0)) {
      throw UsageError("--cluster-radius must be 'auto' or a number in [1, 4], not '" + cluster_radius_ + "'");
    }
    choice.cluster_radius_auto = false;
    choice.cluster_radius_factor = radius;
  }
  return choice;
}

}  // namespace pliant::cli
