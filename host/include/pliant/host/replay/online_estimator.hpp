// The online msm_beta estimator (pliant/core/online_deformability.hpp) on a recording's MSM model,
// stepped frame by frame: what `pliant replay` runs on the frames its particle observer delivers,
// and pliant.OnlineEstimator in Python (host/python).
//
// The model is the recording's (build_msm_model with the default set-up: the rest shape from the
// still frames, fixed particles pinned, every driven particle drivable). Each update drives the
// recording's driven particles to their positions in the frame while their windows are active at
// the frame's recorded time, steps every candidate by dt and scores the rest. The estimator's
// fixed memory is carved once, in the constructor; update allocates nothing. Host code: the
// constructor throws std::runtime_error ("online estimator: <status>") when the model or the
// estimator cannot be set up.
#pragma once

#include <cstdint>
#include <memory>

#include "pliant/core/online_deformability.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {

namespace detail {
class OnlineEstimatorBase;  // one per dimension, in online_estimator.cpp
}

class OnlineRecordingEstimator {
 public:
  /// `recording` must outlive the estimator: its driven windows are read at every update.
  OnlineRecordingEstimator(const Recording& recording, const OnlineDeformabilityConfig& config, double msm_alpha);
  ~OnlineRecordingEstimator();
  OnlineRecordingEstimator(const OnlineRecordingEstimator&) = delete;
  OnlineRecordingEstimator& operator=(const OnlineRecordingEstimator&) = delete;

  /// One frame: `positions` [particle_count * dimension], particle-major, in the recording's
  /// length unit, non-finite where unobserved; `recorded_t_s` decides which driven windows are
  /// active; `dt_s` is the time since the previous frame. Returns the core's status (ok,
  /// invalid_argument for a refused frame, no_observations).
  Status update(const double* positions, double recorded_t_s, double dt_s);
  OnlineDeformabilityEstimate estimate() const;
  /// Back to rest with no evidence (a new grasp).
  void reset();
  std::uint32_t rejected_frames() const;  ///< frames refused (bad dt, ...)
  std::uint32_t empty_frames() const;     ///< frames with no free particle observed

 private:
  std::unique_ptr<detail::OnlineEstimatorBase> estimator_;
};

}  // namespace pliant::host
