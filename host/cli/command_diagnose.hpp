// `pliant diagnose REC`: where the elastic model disagrees with a recording and which physics
// it left out (docs/spec/diagnosis-v1.md).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "model_form_options.hpp"

namespace pliant::cli {

class DiagnoseCommand {
 public:
  explicit DiagnoseCommand(CLI::App& parent);
  bool selected() const { return app_->parsed(); }
  /// Runs after a successful parse; throws on failure (see exit_status.hpp for the mapping).
  int run() const;

 private:
  CLI::App* app_ = nullptr;
  std::string recording_;
  std::string json_path_;
  std::string report_dir_;
  std::string model_ = "msm";
  ModelFormOptions model_form_;  ///< the MSM baseline's msm_alpha and steps per frame
  bool quiet_ = false;
};

}  // namespace pliant::cli
