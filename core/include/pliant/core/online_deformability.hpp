// Online deformability: an msm_beta estimate updated frame by frame during a grasp.
//
// A bank of K MSM simulations, one per candidate msm_beta on a uniform grid over [0, 1], is
// stepped with every frame, driven by the observed tool contact exactly as the trajectory mode
// of deformability.hpp does. Each candidate accumulates the squared residual of the free
// observed particles (optionally with exponential forgetting, for objects whose stiffness may
// change). The estimate is the vertex of the parabola through the best candidate and its
// neighbours; its uncertainty comes from that parabola's curvature (curve_analysis.hpp).
//
// Real-time contract: online_deformability_update costs K MSM steps plus O(K N); it allocates
// nothing and throws nothing. Memory: K MSM states, carved once at init.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pliant/core/msm.hpp"

namespace pliant {

struct OnlineDeformabilityConfig {
  int candidates = 11;      ///< K >= 3, msm_beta = k / (K - 1)
  double forgetting = 1.0;  ///< per-frame weight of past residuals, (0, 1]; 1 keeps everything
};

struct OnlineDeformabilityEstimate {
  double msm_beta = 0;
  double msm_beta_std = 0;  ///< +inf until the curve has positive curvature
  bool unique_minimum = false;
  double rms = 0;            ///< rms residual of the best candidate, length unit
  std::uint32_t frames = 0;  ///< frames accepted so far
};

template <int Dim, typename Scalar>
struct OnlineDeformability {
  int candidates = 0;
  MsmParams<Dim, Scalar> params;            ///< base parameters; msm_beta is set per candidate
  MsmState<Dim, Scalar>* states = nullptr;  ///< [candidates]
  double* sum_squares = nullptr;            ///< [candidates], forgetting applied
  double residual_count = 0;                ///< scalar residuals, forgetting applied
  double forgetting = 1;
  std::uint32_t frames = 0;
  std::uint32_t rejected_frames = 0;  ///< bad dt, size mismatch
  std::uint32_t empty_frames = 0;     ///< frames with no free particle observed
  bool initialized() const noexcept { return states != nullptr; }
};

template <int Dim, typename Scalar>
std::size_t online_deformability_workspace_size(const MsmModel<Dim, Scalar>& model,
                                                const OnlineDeformabilityConfig& config) noexcept;

/// Carves K states from `arena` and resets them to rest. `base` holds msm_alpha, gravity,
/// damping and plasticity used by every candidate. Init time only.
template <int Dim, typename Scalar>
[[nodiscard]] Status online_deformability_init(Arena& arena, const MsmModel<Dim, Scalar>& model,
                                               const MsmParams<Dim, Scalar>& base,
                                               const OnlineDeformabilityConfig& config,
                                               OnlineDeformability<Dim, Scalar>& estimator) noexcept;

/// Back to rest with no evidence (a new grasp). Real-time safe.
template <int Dim, typename Scalar>
void online_deformability_reset(const MsmModel<Dim, Scalar>& model,
                                OnlineDeformability<Dim, Scalar>& estimator) noexcept;

/// Advances every candidate by dt (seconds since the previous frame) with the driven targets,
/// then scores them against `observed` ([particle_count] positions; a non-finite entry is
/// unobserved). Returns ok, invalid_argument (frame rejected and counted) or
/// no_observations (frame used for stepping, nothing scored, counted).
template <int Dim, typename Scalar>
[[nodiscard]] Status online_deformability_update(const MsmModel<Dim, Scalar>& model,
                                                 OnlineDeformability<Dim, Scalar>& estimator, Scalar dt,
                                                 const MsmDrivenTargets<Dim, Scalar>& driven,
                                                 const Eigen::Matrix<Scalar, Dim, 1>* observed) noexcept;

/// The current estimate. O(K), real-time safe.
template <int Dim, typename Scalar>
OnlineDeformabilityEstimate online_deformability_estimate(const OnlineDeformability<Dim, Scalar>& estimator) noexcept;

}  // namespace pliant
