// `pliant simulate SCENARIO -o DIR`: a simulated recording with known ground truth.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "pliant/host/scenarios.hpp"

namespace pliant::cli {

class SimulateCommand {
 public:
  /// Registers the subcommand and its options on `parent`.
  explicit SimulateCommand(CLI::App& parent);

  bool selected() const { return app_->parsed(); }
  /// Runs after a successful parse; throws on failure (see exit_status.hpp for the mapping).
  int run() const;

 private:
  CLI::App* app_ = nullptr;
  std::string scenario_;
  std::string output_;
  host::ScenarioOptions options_;
  bool force_ = false;
};

}  // namespace pliant::cli
