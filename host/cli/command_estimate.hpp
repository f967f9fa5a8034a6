// `pliant estimate REC`: msm_beta (and optionally msm_alpha) of a recording.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "model_form_options.hpp"

namespace pliant::cli {

class EstimateCommand {
 public:
  /// Registers the subcommand and its options on `parent`.
  explicit EstimateCommand(CLI::App& parent);

  bool selected() const { return app_->parsed(); }
  /// Runs after a successful parse; throws on failure (see exit_status.hpp for the mapping).
  int run() const;

 private:
  CLI::App* app_ = nullptr;
  std::string recording_;
  std::string json_path_;
  std::string mode_ = "trajectory";
  ModelFormOptions model_form_;
  int grid_points_ = 11;
  bool quiet_ = false;
};

}  // namespace pliant::cli
