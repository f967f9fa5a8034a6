// Meshless shape matching: per-run state and the real-time step (Algorithm 1 with clusters).
//
// One step advances the state by dt seconds:
//   1. predict  v' = v + dt (g + f/m) (then velocity damping), x' = x + dt v'   (eqs. 1-2)
//      fixed particles: x' = rest; driven particles: x' = their target this step;
//   2. per cluster c: centroid t, A_pq = sum m (x' - t) q0^T, A = A_pq A_qq^+,
//      R = rotation of A_pq (polar), goal g = ((1 - beta_c) R + beta_c A) q + t   (eqs. 3-12);
//   3. average each particle's goals over the clusters holding it (eq. 13), then
//      x = x' + alpha (g - x'), v = (x - x_old) / dt                               (eqs. 10-11).
// With plasticity on (plastic_creep > 0), each cluster carries a plastic deformation S_p that
// yields and creeps toward the cluster's strain (Mueller et al. 2005, section 4.4); rest offsets
// become S_p q0. Relaxation, stiffening and support friction (MsmParams) extend the model the
// same way; each reduces exactly to the elastic model at its null value, which is what lets
// `diagnose` test whether the data need it.
//
// Real-time contract: msm_step and msm_state_reset are O(memberships + clusters), allocate
// nothing, throw nothing. Non-finite inputs never reach the state: a NaN target is dropped
// (counted in dropped_targets, the particle holds its previous position) and a bad dt or force
// rejects the whole step (counted in rejected_steps, state unchanged). A target for a particle
// that is not drivable (or is fixed) is dropped and counted; that particle moves freely.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "pliant/core/msm_model.hpp"

namespace pliant {

template <int Dim, typename Scalar>
struct MsmParams {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  Scalar msm_alpha = 1;  ///< (0, 1]: fraction of the way to the goal per step (1 = paper)
  Scalar msm_beta = 0;   ///< [0, 1]: 0 rigid clusters, 1 fully affine (deformable)
  /// Optional per-cluster msm_beta ([cluster_count], caller memory); overrides msm_beta.
  const Scalar* cluster_beta = nullptr;
  Vec gravity = Vec::Zero();    ///< body acceleration, length unit / s^2
  Scalar velocity_damping = 0;  ///< 1/s: v' *= max(0, 1 - velocity_damping * dt)
  /// Plasticity: off while plastic_creep == 0. Yield and max are Frobenius norms of strain.
  Scalar plastic_yield = 0;
  Scalar plastic_creep = 0;  ///< 1/s
  Scalar plastic_max = 1;
  /// Viscoelastic relaxation (off while relaxation_fraction == 0): a share g1 of each cluster's
  /// rest shape relaxes toward its current strain with time constant relaxation_time_s, so
  /// the object creeps under a held load and recovers slowly after release.
  Scalar relaxation_fraction = 0;  ///< g1 in [0, 1)
  Scalar relaxation_time_s = 1;    ///< tau, s, > 0
  /// Strain stiffening (off while 0): cluster beta = beta / (1 + stiffening * |strain|), with
  /// |strain| the Frobenius norm of sym(R^T A) - I.
  Scalar stiffening = 0;
  /// Support friction: infinity (default) pins `fixed` particles at rest. Finite mu keeps them
  /// in their support plane (through their rest position, normal `support_normal`) but lets
  /// them slide along it when the tangential move exceeds mu times the normal correction the
  /// plane applies that step (Coulomb friction in position form; the normal correction stands
  /// in for the normal force). mu -> infinity is the pin.
  Scalar support_friction = std::numeric_limits<Scalar>::infinity();
  Vec support_normal = Vec::Zero();  ///< unit vector; required when support_friction is finite
};

/// Per-cluster rotation kept between steps: the 2D matrix or the 3D quaternion warm start.
template <int Dim, typename Scalar>
using ClusterRotation = std::conditional_t<Dim == 2, Eigen::Matrix<Scalar, 2, 2>, Eigen::Quaternion<Scalar>>;

template <int Dim, typename Scalar>
struct MsmState {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  using Mat = Eigen::Matrix<Scalar, Dim, Dim>;
  Vec* position = nullptr;   ///< [particle_count]
  Vec* velocity = nullptr;   ///< [particle_count], length unit / s
  Vec* predicted = nullptr;  ///< [particle_count] scratch
  /// Step scratch: per particle [m x q^T | m x] and per cluster the goal map [G | b] with
  /// goal = G r + b (both relative to the origins in MsmModel::rest_origin and the step's mean).
  Eigen::Matrix<Scalar, Dim, Dim + 1>* moment = nullptr;            ///< [particle_count]
  Eigen::Matrix<Scalar, Dim, Dim + 1>* cluster_goal_map = nullptr;  ///< [cluster_count]
  std::uint8_t* driven_now = nullptr;                ///< [particle_count] 1 while driven in the last step
  ClusterRotation<Dim, Scalar>* rotation = nullptr;  ///< [cluster_count]
  Mat* plastic = nullptr;                            ///< [cluster_count] S_p, identity when no plastic set
  Mat* relaxed = nullptr;                            ///< [cluster_count] relaxed strain V (identity at rest)
  double time_s = 0;                                 ///< sum of accepted dt
  std::uint32_t steps = 0;
  std::uint32_t dropped_targets = 0;  ///< driven targets ignored for being non-finite
  std::uint32_t rejected_steps = 0;   ///< steps refused (bad dt, non-finite force)
  bool initialized() const noexcept { return position != nullptr; }
};

/// Targets for particles driven during this step (the tool contact). Ids must be drivable;
/// others are dropped and counted. Caller memory, read during the call only.
template <int Dim, typename Scalar>
struct MsmDrivenTargets {
  const int* ids = nullptr;
  const Eigen::Matrix<Scalar, Dim, 1>* positions = nullptr;
  int count = 0;
};

template <int Dim, typename Scalar>
struct MsmStepInput {
  Scalar dt = 0;  ///< seconds, finite and > 0
  MsmDrivenTargets<Dim, Scalar> driven;
  /// Optional external forces [particle_count] in N (mass unit x length unit / s^2).
  const Eigen::Matrix<Scalar, Dim, 1>* external_force = nullptr;
};

template <int Dim, typename Scalar>
std::size_t msm_state_workspace_size(const MsmModel<Dim, Scalar>& model) noexcept;

/// Carves the state for `model` out of `arena` and resets it. Init time only.
template <int Dim, typename Scalar>
[[nodiscard]] Status msm_state_init(Arena& arena, const MsmModel<Dim, Scalar>& model,
                                    MsmState<Dim, Scalar>& state) noexcept;

/// Back to rest: positions = rest, zero velocity, identity rotations and plastic state,
/// counters kept. Real-time safe, O(N + C).
template <int Dim, typename Scalar>
void msm_state_reset(const MsmModel<Dim, Scalar>& model, MsmState<Dim, Scalar>& state) noexcept;

/// One simulation step (see top of file). Returns ok, or non_finite_input when a target was
/// dropped (the step still ran), or invalid_argument / non_finite_input when the step was
/// rejected (state unchanged), or not_initialized.
template <int Dim, typename Scalar>
[[nodiscard]] Status msm_step(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& params,
                              const MsmStepInput<Dim, Scalar>& input, MsmState<Dim, Scalar>& state) noexcept;

}  // namespace pliant
