// `pliant record [--color SPEC] [--depth SPEC] [--ft SPEC] [--gripper SPEC] [--duration S]
//  [--roi x,y,w,h | --mask PNG] [--grid RxC] [--spacing PX] [--flow dis|farneback] [--support ...]
//  [--driven ...] [--tare] [--gripper-stroke M] [--force] -o REC`: records any mix of devices on
// one clock (hal::SteadyClock) into a recording (v1) with its media: wrench.csv, gripper.csv or
// gripper_state.csv, color.avi + color_frames.csv, depth/NNNNNN.png + depth_frames.csv, and the
// particles (tracked in the colour video with --roi/--mask, else the gripper's jaws).
// docs/record.md has the details; the parts are record_*.hpp.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "record_track.hpp"

namespace pliant::cli {

class RecordCommand {
 public:
  /// Registers `record` on `parent`.
  explicit RecordCommand(CLI::App& parent);

  bool selected() const { return app_->parsed(); }
  /// Runs after a successful parse; throws on failure (see exit_status.hpp for the mapping).
  int run() const;

 private:
  CLI::App* app_ = nullptr;
  std::string color_;
  std::string depth_;
  std::string ft_;
  std::string gripper_;
  double duration_s_ = 0;
  TrackRequest track_;
  bool tare_ = false;
  double gripper_stroke_m_ = 0.085;
  std::string output_;
  bool force_ = false;
  bool quiet_ = false;
};

}  // namespace pliant::cli
