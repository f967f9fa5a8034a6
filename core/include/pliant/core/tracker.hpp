// MSM-regularised particle tracker: noisy, partial observations in, physically plausible
// particle trajectories out, one frame at a time.
//
// Per frame (tracker_update):
//   1. predict: one msm_step of the object's MSM model over dt, driven by the tool contact
//      (the same model and driving the estimators use), from the previous tracked state;
//   2. residuals r_i = observed_i - predicted_i for every particle with a finite observation
//      (and confidence > 0). The model's own error is spatially smooth; a wrong match is not.
//      So each cluster takes the component-wise median of its members' residuals (fixed and
//      driven members count with residual zero: their position is known), each
//      particle the mean of those medians over its clusters (m_i, the local coherent motion
//      the model missed), e_i = r_i - m_i, and a robust per-axis scale
//      s = max(min_residual_scale, median d_i / m_Dim), m_Dim the median norm of a unit
//      isotropic Gaussian (1.1774 in 2D, 1.5382 in 3D);
//   3. Tukey biweight on the discrepancy d_i = min(|r_i|, |e_i|) (an observation is plausible
//      if it agrees with the prediction or with its neighbours' coherent motion):
//      w_i = confidence_i x (1 - (d_i / (tukey_c s))^2)^2 for d_i < tukey_c s, else 0 (an
//      outlier: a wrong flow vector, a point on an occluder);
//   4. correct (weighted least squares between prior and observation): an observation with
//      weight w moves its particle by w / (w + lambda) x r_i, lambda = 1 / observation_gain - 1
//      (the default gain 1 follows every inlier exactly: no smoothing, so no lag that would
//      bias msm_beta; a gain below 1 smooths noise at the cost of lag under model error).
//      The velocity takes the same correction / dt, so the model carries it into the next
//      prediction;
//   5. regularise: particles without a usable observation are then moved to the shape-matching
//      goal of the corrected configuration (cluster shape matching with the current msm_beta,
//      eqs. 3-13 of the MSM paper, averaged over the clusters holding them),
//      projection_iterations times. An occluded particle so follows its observed neighbours the
//      way the object deforms, instead of drifting on its own.
//   6. a rejected observation is looked at once more against where the corrected
//      neighbourhood now puts its particle, and re-admitted if within the cutoff (a steep but
//      real deformation next to the tool).
// A particle with no usable observation for more than max_unobserved_frames frames is
// reported lost (it is still tracked by the model; a usable observation makes it observed
// again).
//
// Units and frames: the MSM model's (length unit, one fixed frame, seconds). The tracker's
// state starts at the model's rest shape: build the model from the first (still) frame.
//
// Lifecycle and memory (no heap, ever):
//   std::size_t bytes = tracker_workspace_size(model, config);   // init time
//   Arena arena(block, bytes);                                     // caller-owned
//   Status s = tracker_init(arena, model, params, config, tracker); // init time
//   per frame: tracker_update (real-time: O(Dim x memberships x (1 + projection_iterations))
//   with linear-time medians; allocates nothing, throws nothing).
// The model must outlive the tracker. The block must outlive the tracker.
// Thread safety: one tracker per thread; no internal locking.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pliant/core/msm.hpp"

namespace pliant {

struct TrackerConfig {
  double tukey_c = 4.685;  ///< Tukey cutoff in robust-scale units, > 0 (95 % Gaussian efficiency)
  /// Floor of the robust residual scale, length unit, >= 0: set it to the observation noise sd
  /// per axis. Below it nothing is an outlier, so it also keeps noise-free data with a model
  /// error from being rejected. 0 uses 0.02 x the model's rest spacing (the median
  /// nearest-neighbour distance; 2 px for particles 100 px apart).
  double min_residual_scale = 0;
  double observation_gain = 1.0;   ///< (0, 1]: blend toward a fully weighted observation (1: follow it)
  int projection_iterations = 2;   ///< >= 0 shape-matching passes for particles without observation
  int max_unobserved_frames = 30;  ///< >= 1 frames without a usable observation before "lost"
};

enum class TrackStatus : std::uint8_t {
  observed = 0,   ///< corrected toward a usable observation this frame
  predicted = 1,  ///< no usable observation this frame (occluded, outlier): follows the model
  lost = 2,       ///< no usable observation for more than max_unobserved_frames frames
};

/// One frame of input.
template <int Dim, typename Scalar>
struct TrackerFrame {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  Scalar dt = 0;                         ///< s since the previous frame, finite > 0
  MsmDrivenTargets<Dim, Scalar> driven;  ///< tool contact targets this frame (may be empty)
  /// [particle_count] observed positions; a non-finite entry is unobserved. nullptr: no
  /// observation this frame (the frame is pure prediction).
  const Vec* observed = nullptr;
  /// Optional [particle_count] observation confidence in [0, 1] (e.g. a flow consistency
  /// score); nullptr: 1 for every observed particle. Non-finite or <= 0: unobserved.
  const Scalar* confidence = nullptr;
};

/// Monotonic counters (wrap at 2^32).
struct TrackerCounters {
  std::uint32_t frames = 0;           ///< frames accepted
  std::uint32_t rejected_frames = 0;  ///< frames refused (bad dt, non-finite target): state unchanged
  std::uint32_t observations = 0;     ///< observations used with weight > 0
  std::uint32_t outliers = 0;         ///< finite observations given weight 0
  std::uint32_t unobserved = 0;       ///< particle-frames without a finite observation
  std::uint32_t lost_events = 0;      ///< transitions of a particle to lost
  std::uint32_t empty_frames = 0;     ///< frames without any usable observation
};

template <int Dim, typename Scalar>
struct Tracker {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  TrackerConfig config;  ///< validated copy
  /// The prior's parameters. msm_beta may be changed between frames (e.g. fed back from the
  /// online estimate); cluster_beta, if set, must outlive the tracker.
  MsmParams<Dim, Scalar> params;
  MsmState<Dim, Scalar> state;                ///< state.position: the tracked positions [particle_count]
  Scalar* weight = nullptr;                   ///< [particle_count] last frame's weight (0: not used)
  TrackStatus* status = nullptr;              ///< [particle_count]
  std::int32_t* unobserved_frames = nullptr;  ///< [particle_count] consecutive frames without use
  Vec* residual = nullptr;                    ///< [particle_count] last frame's r_i (zero: no usable observation)
  Vec* coherent = nullptr;                    ///< [particle_count] last frame's m_i
  Vec* cluster_residual = nullptr;            ///< [cluster_count] median residual (NaN: no usable member)
  /// [particle_count] scratch: 1 usable observation this frame, 2 held (fixed or driven: known
  /// exactly, a zero residual for the cluster medians), 0 neither.
  std::uint8_t* usable = nullptr;
  Scalar* scratch = nullptr;      ///< [max(particle_count, largest cluster)] median scratch
  Vec* goal = nullptr;            ///< [particle_count] projection scratch
  Scalar residual_scale = 0;      ///< last frame's robust scale s (per axis), length unit
  std::uint32_t frame_index = 0;  ///< frames accepted since init or reset
  TrackerCounters counters;
  bool initialized() const noexcept { return weight != nullptr; }
};

/// Bytes of caller memory tracker_init needs (0 when the model is not initialised).
template <int Dim, typename Scalar>
std::size_t tracker_workspace_size(const MsmModel<Dim, Scalar>& model, const TrackerConfig& config) noexcept;

/// Validates `config` and `params`, carves the state and resets it to the rest shape. Init time
/// only. Errors: not_initialized (model), invalid_argument (a field out of its documented
/// range), capacity_exceeded. On error the tracker is left uninitialised.
template <int Dim, typename Scalar>
[[nodiscard]] Status tracker_init(Arena& arena, const MsmModel<Dim, Scalar>& model,
                                  const MsmParams<Dim, Scalar>& params, const TrackerConfig& config,
                                  Tracker<Dim, Scalar>& tracker) noexcept;

/// Back to the rest shape, at rest, every particle observed-fresh; counters kept. Real-time safe.
template <int Dim, typename Scalar>
void tracker_reset(const MsmModel<Dim, Scalar>& model, Tracker<Dim, Scalar>& tracker) noexcept;

/// One frame (see the top of the file). Returns ok; no_observations (the frame was predicted
/// and regularised with nothing to correct toward; counted); invalid_argument (dt not finite
/// > 0, a tool target id not drivable, or params changed to invalid values: frame refused and
/// counted, state unchanged); not_initialized. A non-finite tool target is dropped and counted
/// in state.dropped_targets (the contact particle holds); the frame is still used.
/// Real-time safe.
template <int Dim, typename Scalar>
[[nodiscard]] Status tracker_update(const MsmModel<Dim, Scalar>& model, Tracker<Dim, Scalar>& tracker,
                                    const TrackerFrame<Dim, Scalar>& frame) noexcept;

}  // namespace pliant
