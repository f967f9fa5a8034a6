// `pliant track-depth PLAN DEPTH -o DIR` (or `--seed-spacing M DEPTH` without a plan): a depth
// image sequence (TUM list, `pliant record` depth_frames.csv, .oni) tracked into a 3D recording (host/vision/depth,
// docs/vision_depth.md).
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "cli_registry.hpp"

namespace pliant::cli {

class TrackDepthCommand final : public OptionalCommand {
 public:
  /// Registers the subcommand and its options on `parent`.
  explicit TrackDepthCommand(CLI::App& parent);

  bool selected() const override { return app_->parsed(); }
  /// Runs after a successful parse; throws on failure (see exit_status.hpp for the mapping).
  int run() const override;

 private:
  CLI::App* app_ = nullptr;
  std::vector<std::string> positionals_;  // [PLAN] DEPTH
  std::string output_;
  std::string intrinsics_;
  std::string camera_pose_;
  std::string region_;
  std::string correspondence_ = "plane";
  double units_per_metre_ = 1000.0;
  int stride_ = 1;
  double min_depth_m_ = 0.0;
  double max_depth_m_ = 0.0;
  double noise_m_ = 1e-3;
  double msm_beta_ = 0.5;
  double time_offset_s_ = 0.0;
  double seed_spacing_m_ = 0.0;
  int rounds_ = 1;
  int reference_frames_ = 15;
  bool all_tracked_ = false;
  bool force_ = false;
};

/// Adds the command to the registry's optional commands (compiled only when the depth front end is built; called
/// by the generated registration of cli_registry.hpp).
void register_track_depth_command(CliRegistry& registry);

}  // namespace pliant::cli
