#include "pliant/core/tracker.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "pliant/core/polar.hpp"

namespace pliant {
namespace {

template <typename Scalar>
bool finite(Scalar value) noexcept {
  return std::isfinite(value);
}

// Median of |r| for an isotropic Gaussian residual of unit sd per axis: the Rayleigh (2D) and
// Maxwell (3D) medians. Dividing the median residual norm by it gives the per-axis sd.
template <int Dim>
constexpr double gaussian_norm_median() noexcept {
  return Dim == 2 ? 1.1774100225154747 : 1.5381722544550522;
}

// Default floor of the residual scale, as a fraction of the rest spacing (see TrackerConfig).
constexpr double kDefaultScaleFraction = 0.02;

bool config_valid(const TrackerConfig& config) noexcept {
  return std::isfinite(config.tukey_c) && config.tukey_c > 0 && std::isfinite(config.min_residual_scale) &&
         config.min_residual_scale >= 0 && std::isfinite(config.observation_gain) && config.observation_gain > 0 &&
         config.observation_gain <= 1 && config.projection_iterations >= 0 && config.projection_iterations <= 64 &&
         config.max_unobserved_frames >= 1;
}

template <int Dim, typename Scalar>
Status layout(Arena& arena, const MsmModel<Dim, Scalar>& model, Tracker<Dim, Scalar>& tracker) noexcept {
  const auto n = static_cast<std::size_t>(model.particle_count);
  const Status state_status = msm_state_init(arena, model, tracker.state);
  tracker.weight = arena.carve<Scalar>(n);
  tracker.status = arena.carve<TrackStatus>(n);
  tracker.unobserved_frames = arena.carve<std::int32_t>(n);
  using Vec = typename Tracker<Dim, Scalar>::Vec;
  std::int32_t largest_cluster = 0;
  for (int c = 0; c < model.cluster_count; ++c) {
    largest_cluster = std::max(largest_cluster, model.cluster_begin[c + 1] - model.cluster_begin[c]);
  }
  tracker.residual = arena.carve<Vec>(n);
  tracker.coherent = arena.carve<Vec>(n);
  tracker.cluster_residual = arena.carve<Vec>(static_cast<std::size_t>(model.cluster_count));
  tracker.usable = arena.carve<std::uint8_t>(n);
  tracker.scratch = arena.carve<Scalar>(std::max(n, static_cast<std::size_t>(largest_cluster)));
  tracker.goal = arena.carve<Vec>(n);
  if (state_status != Status::ok || arena.exhausted()) return Status::capacity_exceeded;
  return Status::ok;
}

// Rotation maximising trace(R^T A), warm-started from the cluster's last answer.
template <typename Scalar>
Eigen::Matrix<Scalar, 2, 2> cluster_rotation(const Eigen::Matrix<Scalar, 2, 2>& apq,
                                             Eigen::Matrix<Scalar, 2, 2>& warm) noexcept {
  (void)extract_rotation(apq, warm);
  return warm;
}
template <typename Scalar>
Eigen::Matrix<Scalar, 3, 3> cluster_rotation(const Eigen::Matrix<Scalar, 3, 3>& apq,
                                             Eigen::Quaternion<Scalar>& warm) noexcept {
  Eigen::Matrix<Scalar, 3, 3> rotation;
  (void)extract_rotation(apq, warm, rotation, 8, simulation_rotation_tolerance<Scalar>());
  return rotation;
}

// One shape-matching pass over the current positions: goal[i] = mean over the clusters holding
// i of ((1 - beta) R + beta A) q0 + t (eqs. 3-13, elastic). Particles in no cluster keep their
// position as goal.
template <int Dim, typename Scalar>
void shape_matching_goals(const MsmModel<Dim, Scalar>& model, Tracker<Dim, Scalar>& tracker) noexcept {
  using Vec = typename Tracker<Dim, Scalar>::Vec;
  using Mat = Eigen::Matrix<Scalar, Dim, Dim>;
  const int n = model.particle_count;
  const Vec* const x = tracker.state.position;
  Vec* const goal = tracker.goal;
  for (int i = 0; i < n; ++i) goal[i].setZero();
  for (int c = 0; c < model.cluster_count; ++c) {
    const int begin = model.cluster_begin[c];
    const int end = model.cluster_begin[c + 1];
    Vec centroid = Vec::Zero();
    for (int k = begin; k < end; ++k) centroid += model.mass[model.members[k]] * x[model.members[k]];
    centroid *= model.cluster_inverse_mass[c];
    Mat apq = Mat::Zero();
    for (int k = begin; k < end; ++k) {
      const int i = model.members[k];
      apq.noalias() += model.mass[i] * (x[i] - centroid) * model.member_rest_offset[k].transpose();
    }
    const Mat rotation = cluster_rotation(apq, tracker.state.rotation[c]);
    const Scalar beta =
        tracker.params.cluster_beta != nullptr ? tracker.params.cluster_beta[c] : tracker.params.msm_beta;
    const Mat map = (Scalar(1) - beta) * rotation + beta * (apq * model.cluster_aqq_inverse[c]);
    for (int k = begin; k < end; ++k) goal[model.members[k]] += map * model.member_rest_offset[k] + centroid;
  }
  for (int i = 0; i < n; ++i) {
    if (model.inverse_cluster_count[i] > Scalar(0)) {
      goal[i] *= model.inverse_cluster_count[i];
    } else {
      goal[i] = x[i];
    }
  }
}

// Median of values[0 .. count) (count >= 1; the mean of the two middle values when even).
// Reorders the values. Linear time, no allocation.
template <typename Scalar>
Scalar median_of(Scalar* values, int count) noexcept {
  Scalar* const upper = values + count / 2;
  std::nth_element(values, upper, values + count);
  if (count % 2 != 0) return *upper;
  const Scalar lower = *std::max_element(values, upper);
  return Scalar(0.5) * (lower + *upper);
}

// m_i: per cluster the component-wise median residual of its usable members, averaged over
// the clusters holding i (clusters without a usable member do not count; none: zero).
template <int Dim, typename Scalar>
void coherent_residuals(const MsmModel<Dim, Scalar>& model, Tracker<Dim, Scalar>& tracker) noexcept {
  using Vec = typename Tracker<Dim, Scalar>::Vec;
  for (int c = 0; c < model.cluster_count; ++c) {
    const int begin = model.cluster_begin[c];
    const int end = model.cluster_begin[c + 1];
    Vec median = Vec::Constant(std::numeric_limits<Scalar>::quiet_NaN());
    for (int d = 0; d < Dim; ++d) {
      int count = 0;
      for (int k = begin; k < end; ++k) {
        const int i = model.members[k];
        if (tracker.usable[i] != 0) tracker.scratch[count++] = tracker.residual[i](d);
      }
      if (count == 0) break;
      median(d) = median_of(tracker.scratch, count);
    }
    tracker.cluster_residual[c] = median;
  }
  for (int i = 0; i < model.particle_count; ++i) {
    Vec sum = Vec::Zero();
    int count = 0;
    for (int k = model.particle_cluster_begin[i]; k < model.particle_cluster_begin[i + 1]; ++k) {
      const Vec& median = tracker.cluster_residual[model.particle_clusters[k]];
      if (!median.allFinite()) continue;
      sum += median;
      ++count;
    }
    tracker.coherent[i] = count > 0 ? Vec(sum / static_cast<Scalar>(count)) : Vec(Vec::Zero());
  }
}

// How far an observation is from what the model and its neighbours make plausible: the
// smaller of |r_i| (against the prediction) and |r_i - m_i| (against the neighbourhood's
// coherent motion). A wrong match is far from both; a real deformation the model gets wrong
// is close to its neighbours', and noise on a well-predicted particle is close to the
// prediction even where a wrong match nearby has pulled the neighbourhood's median.
template <int Dim, typename Scalar>
Scalar discrepancy(const Tracker<Dim, Scalar>& tracker, int i) noexcept {
  return std::min(tracker.residual[i].norm(), (tracker.residual[i] - tracker.coherent[i]).norm());
}

template <int Dim, typename Scalar>
bool driven_valid(const MsmModel<Dim, Scalar>& model, const MsmDrivenTargets<Dim, Scalar>& driven) noexcept {
  if (driven.count < 0) return false;
  if (driven.count == 0) return true;
  if (driven.ids == nullptr || driven.positions == nullptr) return false;
  for (int k = 0; k < driven.count; ++k) {
    const int id = driven.ids[k];
    if (id < 0 || id >= model.particle_count || model.drivable[id] == 0 || model.fixed[id] != 0) return false;
  }
  return true;
}

}  // namespace

template <int Dim, typename Scalar>
std::size_t tracker_workspace_size(const MsmModel<Dim, Scalar>& model, const TrackerConfig& config) noexcept {
  (void)config;
  if (!model.initialized()) return 0;
  Arena measure;
  Tracker<Dim, Scalar> scratch;
  (void)layout(measure, model, scratch);
  return measure.required_bytes();
}

template <int Dim, typename Scalar>
Status tracker_init(Arena& arena, const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
                    const TrackerConfig& config, Tracker<Dim, Scalar>& tracker) noexcept {
  tracker = Tracker<Dim, Scalar>{};
  if (!model.initialized()) return Status::not_initialized;
  const bool params_ok = finite(params.msm_alpha) && params.msm_alpha > Scalar(0) && params.msm_alpha <= Scalar(1) &&
                         finite(params.msm_beta) && params.msm_beta >= Scalar(0) && params.msm_beta <= Scalar(1);
  if (!config_valid(config) || !params_ok) return Status::invalid_argument;
  Tracker<Dim, Scalar> built;
  built.config = config;
  built.params = params;
  if (built.config.min_residual_scale == 0) {
    built.config.min_residual_scale = kDefaultScaleFraction * static_cast<double>(model.spacing);
  }
  const Status status = layout(arena, model, built);
  if (status != Status::ok) return status;
  tracker = built;
  tracker_reset(model, tracker);
  return Status::ok;
}

template <int Dim, typename Scalar>
void tracker_reset(const MsmModel<Dim, Scalar>& model, Tracker<Dim, Scalar>& tracker) noexcept {
  PLIANT_ASSERT(tracker.initialized() && model.initialized());
  msm_state_reset(model, tracker.state);
  for (int i = 0; i < model.particle_count; ++i) {
    tracker.weight[i] = Scalar(0);
    tracker.status[i] = TrackStatus::observed;
    tracker.unobserved_frames[i] = 0;
  }
  tracker.residual_scale = static_cast<Scalar>(tracker.config.min_residual_scale);
  tracker.frame_index = 0;
}

template <int Dim, typename Scalar>
Status tracker_update(const MsmModel<Dim, Scalar>& model, Tracker<Dim, Scalar>& tracker,
                      const TrackerFrame<Dim, Scalar>& frame) noexcept {
  using Vec = typename Tracker<Dim, Scalar>::Vec;
  if (!model.initialized() || !tracker.initialized()) return Status::not_initialized;
  const Scalar dt = frame.dt;
  if (!finite(dt) || !(dt > Scalar(0)) || !driven_valid(model, frame.driven)) {
    ++tracker.counters.rejected_frames;
    return Status::invalid_argument;
  }
  const int n = model.particle_count;
  MsmState<Dim, Scalar>& state = tracker.state;

  // 1. Predict. A non-finite tool target is dropped by msm_step (the contact particle holds);
  // the frame's observations are still used.
  MsmStepInput<Dim, Scalar> step;
  step.dt = dt;
  step.driven = frame.driven;
  const Status stepped = msm_step(model, tracker.params, step, state);
  if (stepped == Status::invalid_argument) {  // parameters changed to invalid values between frames
    ++tracker.counters.rejected_frames;
    return Status::invalid_argument;
  }

  // 2. Residuals of the usable observations.
  for (int i = 0; i < n; ++i) {
    tracker.usable[i] = 0;
    tracker.weight[i] = Scalar(0);
    tracker.residual[i].setZero();
    if (state.driven_now[i] != 0 || model.fixed[i] != 0) {
      tracker.usable[i] = 2;  // known exactly: a zero-residual anchor for the cluster medians
      continue;
    }
    if (frame.observed == nullptr) continue;
    const Scalar confidence = frame.confidence != nullptr ? frame.confidence[i] : Scalar(1);
    if (!frame.observed[i].allFinite() || !finite(confidence) || !(confidence > Scalar(0))) continue;
    tracker.usable[i] = 1;
    tracker.residual[i] = frame.observed[i] - state.position[i];
  }
  coherent_residuals(model, tracker);

  // Robust scale of the incoherent part e_i = r_i - m_i.
  int usable = 0;
  for (int i = 0; i < n; ++i) {
    if (tracker.usable[i] == 1) tracker.scratch[usable++] = discrepancy(tracker, i);
  }
  Scalar scale = static_cast<Scalar>(tracker.config.min_residual_scale);
  if (usable > 0) {
    const Scalar median_sd = median_of(tracker.scratch, usable) / static_cast<Scalar>(gaussian_norm_median<Dim>());
    if (finite(median_sd)) scale = std::max(scale, median_sd);
  }
  tracker.residual_scale = scale;

  // 3-4. Tukey weights and the correction; the velocity carries the same correction.
  const Scalar cutoff = static_cast<Scalar>(tracker.config.tukey_c) * scale;
  // observation_gain g is the blend of a fully weighted observation, w / (w + lambda) at w = 1:
  // lambda = 1 / g - 1, the ratio of observation to prior variance.
  const Scalar prior_ratio = static_cast<Scalar>(1.0 / tracker.config.observation_gain - 1.0);
  const Scalar inverse_dt = Scalar(1) / dt;
  int used = 0;
  for (int i = 0; i < n; ++i) {
    const bool held = state.driven_now[i] != 0 || model.fixed[i] != 0;
    if (held) {
      tracker.unobserved_frames[i] = 0;
      tracker.status[i] = TrackStatus::observed;
      continue;
    }
    Vec correction = Vec::Zero();
    if (tracker.usable[i] == 1) {
      const Scalar u = discrepancy(tracker, i) / cutoff;
      if (u < Scalar(1)) {
        const Scalar confidence = frame.confidence != nullptr ? frame.confidence[i] : Scalar(1);
        const Scalar taper = Scalar(1) - u * u;
        tracker.weight[i] = std::min(confidence, Scalar(1)) * taper * taper;
        // Weighted least squares between the prior and the observation: the Tukey weight
        // scales the observation's information, not the step, so an inlier out in the taper
        // is still followed and only the relative trust changes.
        correction = (tracker.weight[i] / (tracker.weight[i] + prior_ratio)) * tracker.residual[i];
      }
    }
    if (tracker.weight[i] > Scalar(0)) {
      ++used;
      ++tracker.counters.observations;
      tracker.unobserved_frames[i] = 0;
      tracker.status[i] = TrackStatus::observed;
    } else {
      if (tracker.usable[i] == 1) {
        ++tracker.counters.outliers;
      } else {
        ++tracker.counters.unobserved;
      }
      if (tracker.unobserved_frames[i] < INT32_MAX) ++tracker.unobserved_frames[i];
      if (tracker.unobserved_frames[i] > tracker.config.max_unobserved_frames) {
        if (tracker.status[i] != TrackStatus::lost) ++tracker.counters.lost_events;
        tracker.status[i] = TrackStatus::lost;
      } else {
        tracker.status[i] = TrackStatus::predicted;
      }
    }
    state.position[i] += correction;
    state.velocity[i] += correction * inverse_dt;
  }

  // 5. Particles without a usable observation follow the shape of the corrected configuration.
  for (int pass = 0; pass < tracker.config.projection_iterations; ++pass) {
    shape_matching_goals(model, tracker);
    for (int i = 0; i < n; ++i) {
      if (tracker.status[i] == TrackStatus::observed || !tracker.goal[i].allFinite()) continue;
      const Vec move = tracker.goal[i] - state.position[i];
      state.position[i] += move;
      state.velocity[i] += move * inverse_dt;
    }
  }

  // 6. A second look at the rejected observations: judged against where the corrected
  // neighbourhood now puts their particle, a real but steep deformation (next to the tool,
  // where the model's error changes fastest) is re-admitted; a wrong match stays out.
  for (int i = 0; i < n; ++i) {
    if (tracker.usable[i] != 1 || tracker.weight[i] > Scalar(0)) continue;
    const Vec residual = frame.observed[i] - state.position[i];
    const Scalar u = residual.norm() / cutoff;
    if (!(u < Scalar(1))) continue;
    const Scalar confidence = frame.confidence != nullptr ? frame.confidence[i] : Scalar(1);
    const Scalar taper = Scalar(1) - u * u;
    tracker.weight[i] = std::min(confidence, Scalar(1)) * taper * taper;
    const Vec correction = (tracker.weight[i] / (tracker.weight[i] + prior_ratio)) * residual;
    state.position[i] += correction;
    state.velocity[i] += correction * inverse_dt;
    --tracker.counters.outliers;
    ++tracker.counters.observations;
    ++used;
    if (tracker.status[i] == TrackStatus::lost) --tracker.counters.lost_events;
    tracker.unobserved_frames[i] = 0;
    tracker.status[i] = TrackStatus::observed;
  }

  ++tracker.frame_index;
  ++tracker.counters.frames;
  if (used == 0) {
    ++tracker.counters.empty_frames;
    return Status::no_observations;
  }
  return Status::ok;
}

#define PLIANT_INSTANTIATE_TRACKER(DIM, SCALAR)                                                                  \
  template std::size_t tracker_workspace_size<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&,                         \
                                                           const TrackerConfig&) noexcept;                       \
  template Status tracker_init<DIM, SCALAR>(Arena&, const MsmModel<DIM, SCALAR>&, const MsmParams<DIM, SCALAR>&, \
                                            const TrackerConfig&, Tracker<DIM, SCALAR>&) noexcept;               \
  template void tracker_reset<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&, Tracker<DIM, SCALAR>&) noexcept;        \
  template Status tracker_update<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&, Tracker<DIM, SCALAR>&,               \
                                              const TrackerFrame<DIM, SCALAR>&) noexcept;

PLIANT_INSTANTIATE_TRACKER(2, float)
PLIANT_INSTANTIATE_TRACKER(2, double)
PLIANT_INSTANTIATE_TRACKER(3, float)
PLIANT_INSTANTIATE_TRACKER(3, double)

}  // namespace pliant
