// `pliant replay REC [--stepped | --speed S] [--faults SCRIPT] [--no-estimate] [--msm-alpha A]
//                    [-o OUT.jsonl]`:
// plays a recording back through the HAL replay devices (particle observer, force/torque
// sensor, gripper), optionally with scripted faults, and estimates msm_beta online from what
// the observer delivers (pliant/host/replay/replay_session.hpp). Writes one JSON object per
// delivered sample or device failure, and prints a summary of every device's counters.
#pragma once

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

namespace pliant::cli {

class ReplayCommand {
 public:
  /// Registers `replay` on `parent`.
  explicit ReplayCommand(CLI::App& parent);

  bool selected() const { return app_->parsed(); }
  /// Runs after a successful parse; throws on failure (see exit_status.hpp for the mapping).
  int run() const;

 private:
  CLI::App* app_ = nullptr;
  std::string recording_;
  bool stepped_ = false;
  double speed_ = 1.0;
  std::string faults_;
  bool no_estimate_ = false;
  std::optional<double> msm_alpha_;
  int settled_row_ = 0;
  std::string output_;
};

}  // namespace pliant::cli
