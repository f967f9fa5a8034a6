#include "pliant/core/msm.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>

#include "pliant/core/polar.hpp"

namespace pliant {
namespace {

template <typename Scalar>
bool finite(Scalar value) noexcept {
  return std::isfinite(value);
}

template <int Dim, typename Scalar>
void identity_rotation(ClusterRotation<Dim, Scalar>& rotation) noexcept {
  rotation.setIdentity();
}

// Rotation of `apq` into a matrix, updating the per-cluster warm start.
template <typename Scalar>
Eigen::Matrix<Scalar, 2, 2> rotation_of(const Eigen::Matrix<Scalar, 2, 2>& apq,
                                        Eigen::Matrix<Scalar, 2, 2>& warm) noexcept {
  (void)extract_rotation(apq, warm);
  return warm;
}
template <typename Scalar>
Eigen::Matrix<Scalar, 3, 3> rotation_of(const Eigen::Matrix<Scalar, 3, 3>& apq,
                                        Eigen::Quaternion<Scalar>& warm) noexcept {
  (void)extract_rotation(apq, warm, 24, simulation_rotation_tolerance<Scalar>());
  return warm.toRotationMatrix();
}

// Mueller 2005 plasticity: the plastic state creeps toward the cluster's strain while the
// strain exceeds the yield, is capped at `plastic_max` and kept volume-preserving.
template <int Dim, typename Scalar>
void update_plastic(const MsmParams<Dim, Scalar>& params, Scalar dt,
                    const Eigen::Matrix<Scalar, Dim, Dim>& rotation,
                    const Eigen::Matrix<Scalar, Dim, Dim>& affine_rest,
                    Eigen::Matrix<Scalar, Dim, Dim>& plastic) noexcept {
  using Mat = Eigen::Matrix<Scalar, Dim, Dim>;
  const Scalar plastic_det = plastic.determinant();
  if (!(plastic_det > Scalar(0))) {
    plastic.setIdentity();
    return;
  }
  // A (for the plastically deformed rest shape) = A0 S_p^-1; strain S = R^T A, symmetrised.
  const Mat affine = affine_rest * plastic.inverse();
  const Mat strain_full = rotation.transpose() * affine;
  const Mat strain = Scalar(0.5) * (strain_full + strain_full.transpose());
  const Mat identity = Mat::Identity();
  if ((strain - identity).norm() <= params.plastic_yield) return;
  Mat next = (identity + dt * params.plastic_creep * (strain - identity)) * plastic;
  next = Scalar(0.5) * (next + next.transpose());
  const Scalar excess = (next - identity).norm();
  if (excess > params.plastic_max && excess > Scalar(0)) {
    next = identity + (params.plastic_max / excess) * (next - identity);
  }
  const Scalar det = next.determinant();
  if (!(det > Scalar(0)) || !next.allFinite()) return;
  next /= std::pow(det, Scalar(1) / Scalar(Dim));
  plastic = next;
}

// A support particle in its plane (through its rest position, normal n into the object): the
// normal offset is undone (the support holds it in the plane, as a pin does); the tangential
// move since the last step is cancelled while it is within mu x that normal correction (stick)
// and shortened by that much otherwise (slip). mu -> infinity is the pin exactly.
template <int Dim, typename Scalar>
Eigen::Matrix<Scalar, Dim, 1> support_contact(const MsmParams<Dim, Scalar>& params,
                                              const Eigen::Matrix<Scalar, Dim, 1>& rest,
                                              const Eigen::Matrix<Scalar, Dim, 1>& previous,
                                              Eigen::Matrix<Scalar, Dim, 1> next) noexcept {
  const Eigen::Matrix<Scalar, Dim, 1>& normal = params.support_normal;
  const Scalar correction = normal.dot(rest - next);
  next += correction * normal;
  Eigen::Matrix<Scalar, Dim, 1> slide = next - previous;
  slide -= normal.dot(slide) * normal;
  const Scalar length = slide.norm();
  const Scalar limit = params.support_friction * std::abs(correction);
  if (length <= limit) return next - slide;
  return next - slide * (limit / length);
}

}  // namespace

template <int Dim, typename Scalar>
std::size_t msm_state_workspace_size(const MsmModel<Dim, Scalar>& model) noexcept {
  Arena measure;
  MsmState<Dim, Scalar> scratch;
  (void)msm_state_init(measure, model, scratch);
  return measure.required_bytes();
}

template <int Dim, typename Scalar>
Status msm_state_init(Arena& arena, const MsmModel<Dim, Scalar>& model, MsmState<Dim, Scalar>& state) noexcept {
  using Vec = typename MsmState<Dim, Scalar>::Vec;
  using Mat = typename MsmState<Dim, Scalar>::Mat;
  state = MsmState<Dim, Scalar>{};
  if (!model.initialized()) return Status::not_initialized;
  const auto n = static_cast<std::size_t>(model.particle_count);
  const auto c = static_cast<std::size_t>(model.cluster_count);
  MsmState<Dim, Scalar> s;
  s.position = arena.carve<Vec>(n);
  s.velocity = arena.carve<Vec>(n);
  s.predicted = arena.carve<Vec>(n);
  s.moment = arena.carve<Eigen::Matrix<Scalar, Dim, Dim + 1>>(n);
  s.cluster_goal_map = arena.carve<Eigen::Matrix<Scalar, Dim, Dim + 1>>(c);
  s.driven_now = arena.carve<std::uint8_t>(n);
  s.rotation = arena.carve<ClusterRotation<Dim, Scalar>>(c);
  s.plastic = arena.carve<Mat>(c);
  s.relaxed = arena.carve<Mat>(c);
  if (arena.exhausted()) return Status::capacity_exceeded;
  state = s;
  msm_state_reset(model, state);
  return Status::ok;
}

template <int Dim, typename Scalar>
void msm_state_reset(const MsmModel<Dim, Scalar>& model, MsmState<Dim, Scalar>& state) noexcept {
  PLIANT_ASSERT(state.initialized() && model.initialized());
  for (int i = 0; i < model.particle_count; ++i) {
    state.position[i] = model.rest[i];
    state.velocity[i].setZero();
    state.driven_now[i] = 0;
  }
  for (int c = 0; c < model.cluster_count; ++c) {
    identity_rotation<Dim, Scalar>(state.rotation[c]);
    state.plastic[c].setIdentity();
    state.relaxed[c].setIdentity();
  }
  state.time_s = 0;
  state.steps = 0;
}

template <int Dim, typename Scalar>
Status msm_step(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
                const MsmStepInput<Dim, Scalar>& input, MsmState<Dim, Scalar>& state) noexcept {
  using Vec = typename MsmState<Dim, Scalar>::Vec;
  using Mat = typename MsmState<Dim, Scalar>::Mat;
  if (!model.initialized() || !state.initialized()) return Status::not_initialized;
  const Scalar dt = input.dt;
  const bool params_ok = finite(params.msm_alpha) && params.msm_alpha > Scalar(0) &&
                         params.msm_alpha <= Scalar(1) && finite(params.msm_beta) &&
                         params.msm_beta >= Scalar(0) && params.msm_beta <= Scalar(1) &&
                         params.gravity.allFinite() && finite(params.velocity_damping) &&
                         params.velocity_damping >= Scalar(0) && finite(params.relaxation_fraction) &&
                         params.relaxation_fraction >= Scalar(0) && params.relaxation_fraction < Scalar(1) &&
                         finite(params.relaxation_time_s) && params.relaxation_time_s > Scalar(0) &&
                         finite(params.stiffening) && params.stiffening >= Scalar(0) &&
                         params.support_friction >= Scalar(0) &&
                         (!finite(params.support_friction) ||
                          std::abs(params.support_normal.squaredNorm() - Scalar(1)) < Scalar(1e-3));
  if (!finite(dt) || !(dt > Scalar(0)) || !params_ok || input.driven.count < 0 ||
      (input.driven.count > 0 && (input.driven.ids == nullptr || input.driven.positions == nullptr))) {
    ++state.rejected_steps;
    return Status::invalid_argument;
  }
  const int n = model.particle_count;
  if (input.external_force != nullptr) {
    for (int i = 0; i < n; ++i) {
      if (!input.external_force[i].allFinite()) {
        ++state.rejected_steps;
        return Status::non_finite_input;
      }
    }
  }

  const bool pinned = !finite(params.support_friction);
  // 1. Prediction (eqs. 1-2).
  const Scalar keep = std::max(Scalar(0), Scalar(1) - params.velocity_damping * dt);
  for (int i = 0; i < n; ++i) {
    const Vec& x = state.position[i];
    state.driven_now[i] = 0;
    if (model.fixed[i] != 0 && pinned) {
      state.predicted[i] = model.rest[i];
      continue;
    }
    Vec acceleration = params.gravity;
    if (input.external_force != nullptr) acceleration += input.external_force[i] / model.mass[i];
    const Vec v = (state.velocity[i] + dt * acceleration) * keep;
    state.predicted[i] = x + dt * v;
  }
  Status result = Status::ok;
  for (int k = 0; k < input.driven.count; ++k) {
    const int id = input.driven.ids[k];
    const Vec& target = input.driven.positions[k];
    if (id < 0 || id >= n || model.drivable[id] == 0 || model.fixed[id] != 0) {
      ++state.dropped_targets;
      result = Status::non_finite_input;
      continue;
    }
    if (!target.allFinite()) {
      // Fail safe: the contact particle holds where it was rather than falling free.
      ++state.dropped_targets;
      result = Status::non_finite_input;
      state.predicted[id] = state.position[id];
      state.driven_now[id] = 1;
      continue;
    }
    state.predicted[id] = target;
    state.driven_now[id] = 1;
  }

  // 2. Cluster shape matching (eqs. 3-13). With q0 = r - r_c and sum m q0 = 0,
  // A_pq = sum m x q0^T = sum m x r^T - (sum m x) r_c^T: per-particle moments [m x r^T | m x]
  // are formed once and each cluster sums them, instead of an outer product per membership.
  // Coordinates are taken relative to the mean rest position and the step's mean position so
  // that the cancellation in that difference stays small in float.
  using Moment = Eigen::Matrix<Scalar, Dim, Dim + 1>;
  Vec origin = Vec::Zero();
  for (int i = 0; i < n; ++i) origin += state.predicted[i];
  origin /= static_cast<Scalar>(n);
  for (int i = 0; i < n; ++i) {
    const Vec mx = model.mass[i] * (state.predicted[i] - origin);
    Moment& moment = state.moment[i];
    moment.template leftCols<Dim>().noalias() = mx * (model.rest[i] - model.rest_origin).transpose();
    moment.col(Dim) = mx;
  }
  const bool plastic_on = params.plastic_creep > Scalar(0);
  const bool relax_on = params.relaxation_fraction > Scalar(0);
  const bool stiffen_on = params.stiffening > Scalar(0);
  const bool rest_changes = plastic_on || relax_on;
  // Exact decay of V toward the strain over one step, stable for any dt / tau.
  const Scalar relax_rate = relax_on ? Scalar(1) - std::exp(-dt / params.relaxation_time_s) : Scalar(0);
  for (int c = 0; c < model.cluster_count; ++c) {
    Moment sum = Moment::Zero();
    for (int k = model.cluster_begin[c]; k < model.cluster_begin[c + 1]; ++k) sum += state.moment[model.members[k]];
    const Vec rest_centroid = model.cluster_rest_centroid[c] - model.rest_origin;
    const Mat apq_rest = sum.template leftCols<Dim>() - sum.col(Dim) * rest_centroid.transpose();
    const Vec centroid = sum.col(Dim) * model.cluster_inverse_mass[c];
    const Mat affine_rest = apq_rest * model.cluster_aqq_inverse[c];
    // Rest deformation E: plastic set S_p and relaxed share (1 - g1) I + g1 V (identity when off).
    Mat rest_deformation = Mat::Identity();
    if (rest_changes) {
      rest_deformation = plastic_on ? state.plastic[c] : Mat::Identity();
      if (relax_on) {
        rest_deformation = rest_deformation * ((Scalar(1) - params.relaxation_fraction) * Mat::Identity() +
                                               params.relaxation_fraction * state.relaxed[c]);
      }
    }
    const Mat rotation = rest_changes ? rotation_of(Mat(apq_rest * rest_deformation.transpose()), state.rotation[c])
                                      : rotation_of(apq_rest, state.rotation[c]);
    Scalar beta = params.cluster_beta != nullptr ? params.cluster_beta[c] : params.msm_beta;
    Mat strain = Mat::Zero();  // sym(R^T A) - I, formed only when an effect needs it
    if (stiffen_on || relax_on) {
      const Mat stretch = rotation.transpose() * affine_rest;
      strain = Scalar(0.5) * (stretch + stretch.transpose()) - Mat::Identity();
    }
    if (stiffen_on) beta /= Scalar(1) + params.stiffening * strain.norm();
    // Goal map applied to q0: ((1 - beta) R + beta A) E q0 = (1 - beta) R E q0 + beta A0 q0.
    const Mat goal_map = rest_changes ? Mat((Scalar(1) - beta) * rotation * rest_deformation + beta * affine_rest)
                                      : Mat((Scalar(1) - beta) * rotation + beta * affine_rest);
    // goal(r) = G (r - r_c) + t = G r + (t - G r_c), all relative to the origins.
    Moment& map = state.cluster_goal_map[c];
    map.template leftCols<Dim>() = goal_map;
    map.col(Dim).noalias() = centroid - goal_map * rest_centroid;
    if (plastic_on) update_plastic<Dim, Scalar>(params, dt, rotation, affine_rest, state.plastic[c]);
    if (relax_on) {
      Mat& relaxed = state.relaxed[c];
      const Mat target = strain + Mat::Identity();
      if (target.allFinite()) relaxed += relax_rate * (target - relaxed);
    }
  }

  // 3. Integration (eqs. 10-11) with goals averaged over each particle's clusters.
  const Scalar inverse_dt = Scalar(1) / dt;
  for (int i = 0; i < n; ++i) {
    const Vec previous = state.position[i];
    Vec next;
    if (model.fixed[i] != 0 && pinned) {
      next = model.rest[i];
    } else if (state.driven_now[i] != 0) {
      next = state.predicted[i];  // the goal of a driven particle is its target
    } else if (model.inverse_cluster_count[i] > Scalar(0)) {
      Moment map_sum = Moment::Zero();
      for (int k = model.particle_cluster_begin[i]; k < model.particle_cluster_begin[i + 1]; ++k) {
        map_sum += state.cluster_goal_map[model.particle_clusters[k]];
      }
      const Vec goal_offset = (map_sum.template leftCols<Dim>() * (model.rest[i] - model.rest_origin) + map_sum.col(Dim)) *
                              model.inverse_cluster_count[i];
      next = state.predicted[i] + params.msm_alpha * (origin + goal_offset - state.predicted[i]);
    } else {
      next = state.predicted[i];
    }
    if (model.fixed[i] != 0 && !pinned) next = support_contact(params, model.rest[i], previous, next);
    state.position[i] = next;
    state.velocity[i] = (next - previous) * inverse_dt;
  }
  state.time_s += static_cast<double>(dt);
  ++state.steps;
  return result;
}

#define PLIANT_INSTANTIATE_MSM(DIM, SCALAR)                                                             \
  template std::size_t msm_state_workspace_size<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&) noexcept;   \
  template Status msm_state_init<DIM, SCALAR>(Arena&, const MsmModel<DIM, SCALAR>&, MsmState<DIM, SCALAR>&) noexcept; \
  template void msm_state_reset<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&, MsmState<DIM, SCALAR>&) noexcept;   \
  template Status msm_step<DIM, SCALAR>(const MsmModel<DIM, SCALAR>&, const MsmParams<DIM, SCALAR>&,      \
                                        const MsmStepInput<DIM, SCALAR>&, MsmState<DIM, SCALAR>&) noexcept;
PLIANT_INSTANTIATE_MSM(2, float)
PLIANT_INSTANTIATE_MSM(2, double)
PLIANT_INSTANTIATE_MSM(3, float)
PLIANT_INSTANTIATE_MSM(3, double)
#undef PLIANT_INSTANTIATE_MSM

}  // namespace pliant
