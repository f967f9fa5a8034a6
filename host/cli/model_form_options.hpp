// `--alpha`, `--msm-alpha`, `--steps-per-frame` and `--cluster-radius`: the MSM baseline's model
// form, shared by `pliant estimate` and `pliant diagnose` (docs/estimation.md).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "pliant/host/estimate.hpp"

namespace pliant::cli {

/// What the options chose; the defaults are every choice automatic.
struct ModelFormChoice {
  host::AlphaMode alpha = host::AlphaMode::automatic;
  double msm_alpha = 1.0;   ///< held value
  int steps_per_frame = 0;  ///< 0: automatic
  bool cluster_radius_auto = true;
  double cluster_radius_factor = 1.5;  ///< held value, and the first the automatic choice tries
};

class ModelFormOptions {
 public:
  /// Registers the four options on `app`.
  void add_to(CLI::App& app);

  /// The parsed choice. Throws UsageError naming a bad value.
  ModelFormChoice apply(const CLI::App& app) const;

  /// True when any of the options was given.
  static bool given(const CLI::App& app);

 private:
  std::string alpha_ = "auto";
  std::string steps_per_frame_ = "auto";
  std::string cluster_radius_ = "auto";
  double msm_alpha_ = 1.0;
};

}  // namespace pliant::cli
