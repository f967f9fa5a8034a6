// A tracked video as a recording (docs/spec/recording-v1.md): 2D, length unit "px".
//
//   recording.json  particles.count, fixed = the support particles, driven = the tool particle
//                   (for the whole recording), no gravity (unknown in pixels), meta.camera
//                   and meta.track (source, flow method, window, thresholds, tracker msm_beta,
//                   grid, and whether the roles were detected), files.track = "track.csv";
//   particles.csv   t,id,x,y: a particle's position in the frames where the tracker used an
//                   observation of it; absent (unobserved) in the others, except the driven
//                   particle, whose tracked path is always written because the estimators
//                   drive the simulation with it;
//   track.csv       t,id,x,y,observed,status,check,fb_error_px,similarity: every particle in
//                   every frame at its tracked position (the MSM prediction while unseen), the
//                   tracker status (observed, predicted, lost) and the flow checks' outcome.
// Host code: allocates and throws.
#pragma once

#include <string>

#include "pliant/host/recording.hpp"
#include "pliant/vision/webcam_tracker.hpp"

namespace pliant::vision::webcam {

/// The recording of `result`, named `name`.
host::Recording track_recording(const TrackResult& result, const std::string& name);

/// The text of track.csv.
std::string track_csv_text(const TrackResult& result);

/// Throws InputError when `directory` exists and is not an empty directory (checked before
/// tracking, so that a long run is not lost at the end).
void check_output_directory(const std::string& directory);

/// Writes the recording and track.csv into a temporary directory beside `directory`, then
/// renames it to `directory` (which must not exist or be empty): the recording appears whole
/// or not at all; on failure nothing is left behind. Throws InputError as
/// check_output_directory, std::runtime_error on I/O failure.
void write_track_recording(const TrackResult& result, const std::string& directory);

}  // namespace pliant::vision::webcam
