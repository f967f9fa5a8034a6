// `--alpha`, `--msm-alpha`, `--steps-per-frame` and `--cluster-radius`: the MSM baseline's model
// form, shared by `pliant estimate` and `pliant diagnose` (docs/estimation.md). This registers
// the options; model_form.hpp validates what they say.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "model_form.hpp"

namespace pliant::cli {

class ModelFormOptions {
 public:
  /// Registers the four options on `app`.
  void add_to(CLI::App& app);

  /// What was given on the command line of `app` (options not given stay empty).
  ModelFormText text(const CLI::App& app) const;

 private:
  std::string alpha_ = "auto";
  std::string steps_per_frame_ = "auto";
  std::string cluster_radius_ = "auto";
  double msm_alpha_ = 1.0;
};

}  // namespace pliant::cli
