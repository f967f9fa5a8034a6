// `pliant track VIDEO|IMAGE_PATTERN (--roi x,y,w,h | --mask PNG) [--grid RxC] [--spacing PX]
//  [--flow dis|farneback] [--rate HZ] [--fps HZ] [--window PX] [--support ...] [--driven ...]
//  -o REC`: tracks particles on a grid over the object by dense optical flow, corrected by the
// MSM-regularised tracker, and writes a recording in pixels (docs/vision_webcam.md).
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "cli_registry.hpp"
#include "pliant/vision/webcam_advection.hpp"

namespace pliant::cli {

class TrackCommand final : public OptionalCommand {
 public:
  /// Registers `track` on `parent`.
  explicit TrackCommand(CLI::App& parent);

  bool selected() const override { return app_->parsed(); }
  /// Runs after a successful parse; throws on failure (see exit_status.hpp for the mapping).
  int run() const override;

 private:
  CLI::App* app_ = nullptr;
  std::string input_;
  std::string roi_;
  std::string mask_;
  std::string grid_;
  double spacing_px_ = 0;
  std::string flow_ = "dis";
  double rate_hz_ = 0;
  double fps_hz_ = 0;
  int window_px_ = 10;
  int refine_window_px_ = 9;
  int flow_margin_px_ = vision::webcam::AdvectionConfig{}.flow_margin_px;
  double fb_threshold_px_ = 1.0;
  double min_similarity_ = 0.8;
  double track_beta_ = 0.5;
  std::string support_ = "auto";
  std::string driven_ = "auto";
  std::string output_;
  bool quiet_ = false;
};

/// Adds the command to the registry's optional commands (compiled only when the webcam front end is built; called
/// by the generated registration of cli_registry.hpp).
void register_track_command(CliRegistry& registry);

}  // namespace pliant::cli
