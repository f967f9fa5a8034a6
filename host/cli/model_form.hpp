// The MSM baseline's model form (msm_alpha, steps per frame, cluster radius) as the command line
// and the Python module spell it, and its validation (docs/estimation.md). Shared by `estimate`
// and `diagnose`; no option parser here (model_form_options.hpp registers the options).
#pragma once

#include <optional>
#include <string>

#include "pliant/host/estimate.hpp"

namespace pliant::cli {

/// What was given, as text; an empty optional was not given (the automatic choice).
struct ModelFormText {
  std::optional<std::string> alpha;            ///< --alpha: "auto", "fit" (also ""), "fixed" or "fixed=A"
  std::optional<double> msm_alpha;             ///< --msm-alpha: the same as fixed=A
  std::optional<std::string> steps_per_frame;  ///< --steps-per-frame: "auto" or N in 1..64
  std::optional<std::string> cluster_radius;   ///< --cluster-radius: "auto" or F in [1, 4]
  /// True when any of them was given (even as "auto").
  bool given() const { return alpha || msm_alpha || steps_per_frame || cluster_radius; }
};

/// What the options chose; the defaults are every choice automatic.
struct ModelFormChoice {
  host::AlphaMode alpha = host::AlphaMode::automatic;
  double msm_alpha = 1.0;   ///< held value
  int steps_per_frame = 0;  ///< 0: automatic
  bool cluster_radius_auto = true;
  double cluster_radius_factor = 1.5;  ///< held value, and the first the automatic choice tries
};

/// The choice the text makes. Throws UsageError naming a bad value (the command line's words).
/// --alpha and --msm-alpha together are refused in CLI11's words.
ModelFormChoice model_form_choice(const ModelFormText& text);

}  // namespace pliant::cli
