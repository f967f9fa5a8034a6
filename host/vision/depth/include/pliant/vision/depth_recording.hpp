// A depth sequence tracked into a recording (recording v1, 3D, metres).
//
// The "plan" recording supplies what a depth camera cannot: the particles' rest shape (its
// rest configuration, e.g. mesh nodes or a seeded surface), the fixed support, the driven tool
// contact and its trajectory (robot kinematics, same clock as the depth frames), masses,
// gravity, and any wrench or gripper samples. The depth frames supply the object's surface.
// The result is a recording with one frame per depth frame: frame 0 is the rest shape (at the
// first depth frame's time), frame k the tracked positions after depth frame k.
//
// Host code: allocates and throws (DepthError for depth input, std::runtime_error from the
// model setup, RecordingError never: the plan is already parsed).
#pragma once

#include <functional>
#include <vector>

#include <Eigen/Core>

#include "pliant/host/estimate.hpp"
#include "pliant/host/msm_setup.hpp"
#include "pliant/host/recording.hpp"
#include "pliant/vision/depth_tracker.hpp"

namespace pliant::vision {

struct DepthSequenceOptions {
  DepthTrackerConfig tracker;
  double msm_beta = 0.5;        ///< the tracker's prior, [0, 1]
  double msm_alpha = 1.0;       ///< (0, 1]
  host::MsmSetupOptions setup;  ///< how the model is built from the plan (clusters, rest shape)
  /// true (default): a particle is written in a frame only when the core tracker kept an
  /// observation of it (NaN otherwise; frame 0, fixed and driven particles are always
  /// written): the recording says what the camera saw, and an estimate from it depends little
  /// on msm_beta above. false: every particle's tracked position every frame, occluded and
  /// interior ones as the model moved them, which pulls an estimate toward msm_beta.
  bool observed_only = true;
  /// Leading frames used to calibrate the reference offsets (DepthTracker::calibrate): at
  /// most this many, and only while every tool target is within 5 % of the spacing of its
  /// rest position (the object is untouched). 0: no calibration.
  int reference_frames = 15;
  /// Optional outward rest normals (world, one per particle; zero = interior); empty =
  /// estimate_rest_normals(model).
  std::vector<Eigen::Vector3d> rest_normals;
};

/// Depth frame `index` (0-based), valid until the next call.
using DepthFrameSource = std::function<DepthImageView(int index)>;

struct DepthSequenceResult {
  host::Recording recording;             ///< ready for host::write_recording
  DepthFrameReport alignment;            ///< frame 0 looked at from the rest shape
  std::vector<DepthFrameReport> frames;  ///< one per update (frames 1 ..)
  DepthTrackerCounters counters;
  TrackerCounters core;        ///< the core tracker's counters (lost_events, outliers, ...)
  int calibration_frames = 0;  ///< frames that calibrated the reference offsets
  /// Per frame and particle, frame-major [frame * particle_count + id]: why it was or was not
  /// observed (frame 0: the alignment look at the rest shape).
  std::vector<ParticleView> views;
  /// Per frame and particle, frame-major: the core tracker's status after the frame (frame 0:
  /// observed).
  std::vector<TrackStatus> status;
};

/// Tool targets of `plan` at time t_s: one per driven window active at t_s, the plan's
/// trajectory of that particle interpolated linearly between the frames around t_s (clamped to
/// the first or last frame outside the plan's span). A target whose neighbouring frames do not
/// both observe the particle is NaN (the core drops it and counts it). Clears and fills the
/// vectors.
void driven_targets_at(const host::Recording& plan, double t_s, std::vector<int>& ids,
                       std::vector<Eigen::Vector3d>& positions);

/// Tracks `times_s.size()` depth frames (times strictly increasing, s, the plan's clock).
/// Throws DepthError: plan not 3D or not in metres, fewer than 1 frame, times not strictly
/// increasing or not finite, malformed frames (wrong size), bad options; std::runtime_error
/// when no MSM model can be built from the plan.
DepthSequenceResult track_depth_sequence(const host::Recording& plan, const std::vector<double>& times_s,
                                         const DepthFrameSource& frames, const PinholeIntrinsics& intrinsics,
                                         const DepthSequenceOptions& options);

/// Tracking and estimation in a loop (as STEPE alternates them): track with options.msm_beta
/// as the prior, estimate msm_beta from the tracked recording (host::estimate_recording), track
/// again with that estimate as the prior, and so on, `rounds` times at most (>= 1), stopping
/// early once an estimate moves less than `tolerance` from the prior it was tracked with. A
/// depth camera measures the surface's motion along its normal only; along the surface the
/// tracker keeps the prior's motion, so an estimate from one round still leans a little toward
/// the prior (tests/vision/depth: 0.03 to 0.05 for priors 0.3 off), and a second round removes
/// most of that. The frame source is read once per round, so it must be repeatable.
struct DepthEstimateRounds {
  DepthSequenceResult tracked;                  ///< the last round's tracking
  std::vector<double> priors;                   ///< the prior of each round
  std::vector<host::EstimateReport> estimates;  ///< the estimate of each round
};
DepthEstimateRounds track_and_estimate(const host::Recording& plan, const std::vector<double>& times_s,
                                       const DepthFrameSource& frames, const PinholeIntrinsics& intrinsics,
                                       const DepthSequenceOptions& options, const host::EstimateOptions& estimate,
                                       int rounds = 2, double tolerance = 0.005);

}  // namespace pliant::vision
