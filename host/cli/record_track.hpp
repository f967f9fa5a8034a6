// `pliant record --color ... --roi|--mask`: the particles of a recording tracked by the webcam
// front end (host/vision/webcam, docs/vision_webcam.md) in the colour video just recorded.
//
// The options are those of `pliant track` (--roi or --mask, --grid, --spacing, --flow, --support,
// --driven), parsed and checked before any device is opened; the region and grid are checked
// again against the size of the first colour frame as soon as it arrives, so a region outside
// the frame stops the recording at once rather than after the capture. After the capture the
// front end tracks color.avi frame by frame (no resampling) and each tracked frame takes the
// time of its video frame in color_frames.csv: the particles are on the recording clock.
// Units: px (the recording's length_unit), seconds.
// This header has no OpenCV dependency; record_track.cpp is compiled only when the webcam front
// end is built, and registers its implementation as the CLI's tracking part
// (register_record_tracking, called by the generated registration of cli_registry.hpp).
// Host code: allocates and throws (UsageError for option text and a region that does not fit
// the frames; std::runtime_error when tracking the recorded video fails).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "pliant/host/recording.hpp"

namespace pliant::cli {

/// The tracking options as given on the command line.
struct TrackRequest {
  std::string roi;   ///< "x,y,w,h" px, or empty
  std::string mask;  ///< mask PNG, or empty
  std::string grid;  ///< "RxC", or empty
  double spacing_px = 0;
  std::string flow = "dis";
  std::string support = "auto";
  std::string driven = "auto";
  /// True when a region was given: the particles come from the video.
  bool requested() const { return !roi.empty() || !mask.empty(); }
};

struct CliRegistry;

class VideoTracking {
 public:
  virtual ~VideoTracking() = default;
  VideoTracking(const VideoTracking&) = delete;
  VideoTracking& operator=(const VideoTracking&) = delete;

  /// Seeds the grid on a frame of this size, to check that region and grid fit. Throws UsageError.
  virtual void check_frame_size(int width, int height) const = 0;

  /// Tracks `video`; frame i of the video is at `times_s[i]`. Returns the recording (px,
  /// particles.csv and the track.csv role set) named `name`, and the text of track.csv.
  /// `progress`: draw a progress bar on a terminal. Throws std::runtime_error.
  virtual host::Recording track(const std::string& video, const std::vector<double>& times_s, const std::string& name,
                                std::string& track_csv, bool progress) const = 0;

 protected:
  VideoTracking() = default;
};

/// Sets `registry.tracking` to the webcam front end's tracking: it parses and checks a
/// TrackRequest (reads the mask) and throws UsageError for bad options (record_track.cpp).
void register_record_tracking(CliRegistry& registry);

}  // namespace pliant::cli
