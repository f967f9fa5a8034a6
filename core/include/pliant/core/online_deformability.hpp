// Online deformability: an msm_beta (and msm_alpha) estimate updated frame by frame during a
// grasp.
//
// A bank of A x K MSM simulations is stepped with every frame, driven by the observed tool
// contact exactly as the trajectory mode of deformability.hpp does: K candidate msm_beta on a
// uniform grid over [0, 1] in each row (model form) of A msm_alpha values (A = 1: the base
// msm_alpha only; A >= 2: a uniform grid over [alpha_min, 1], the last alpha 1) times S step
// counts (1, 2, .., 2^(S-1) MSM steps per frame interval, the driven targets interpolated
// linearly within the interval, as deformability.hpp's steps_per_frame). Each candidate accumulates
// the squared residual of the free observed particles (optionally with exponential forgetting,
// for objects whose stiffness may change).
//
// The quasi-static row (equilibrium_iterations = M > 0): K more candidates that do not step
// through the frame interval but relax towards the equilibrium under the frame's driven targets,
// from where they stood at the last frame, with at most M MSM iterations per frame (momentum
// 0.5 + 0.4 msm_beta, as the grasp guard's relaxation; msm_alpha 1, which an equilibrium does
// not depend on), until no particle moves more than equilibrium_tolerance x spacing in two
// successive iterations. It is the form of an object that settles between frames: the HIL's
// plant relaxes with up to 24 MSM steps every 1 ms, hundreds per camera frame, and on its
// squeezes at 20 mm/s the rows of 1 step per frame read msm_beta up to 0.8 low where this row
// reads within 0.03 of the truth (docs/estimation.md, "Online"). It is meant for elastic
// objects: plasticity and viscous relaxation would advance with every iteration.
//
// The estimate (online_deformability_estimate):
//   per row, the vertex of the parabola through the row's best candidate and its neighbours
//   gives that row's msm_beta and least residual (curve_analysis.hpp);
//   the held form is the alpha-1 row at one step per frame; the fitted form is the best row
//   (msm_alpha, steps per frame), refined (A >= 3) by the parabola over msm_alpha through the
//   best row and its neighbours of the same step count, with msm_beta interpolated between the
//   rows' vertices at that alpha;
//   the quasi-static row is a form of its own (no alpha refinement);
//   the fitted form is taken only when the recording determines it: by BIC, with one more
//   parameter for alpha rows, one for step rows and one for the quasi-static row,
//   n ln(S_held / S_fitted) > extra ln n,
//   S_fitted the best simulated row's least residual (not the interpolated one) and n the
//   observed point count (residuals / Dim: one particle in one frame counts once). Otherwise the
//   held row answers.
//   msm_beta_std comes from the curvature of the answering row (conditional on its form); when
//   the fitted form answers, the difference between its msm_beta and the held form's is added in
//   quadrature. The criterion counts correlated residuals as independent, so a form can win on
//   a model-form misfit alone: on the HIL's quasi-statically relaxed carton (true 0.15) the alpha
//   rows answered 1.00 +- 0.002 where the held row said 0.00; with this term the guard's
//   interval spans both, as it must on the safety path.
//
// Real-time contract: online_deformability_update costs A x K x (2^S - 1) MSM steps, plus at
// most K x M with the quasi-static row, plus O((A S + 1) K N); it allocates nothing and throws
// nothing. Memory: (A x S (+ 1)) x K MSM states and two (three) [N] buffers, carved once at init.
//
// The form matters: on presses made by an independent MSM (tools/concealed/msm_world.py) with
// msm_alpha 0.3-0.95 and 1-3 steps per frame, holding alpha 1 at one step put msm_beta 0.09 to
// 0.44 off (docs/estimation.md). The reported msm_alpha is read off a coarse grid (0.35 apart by
// default) and is a nuisance; msm_beta is what the rows are for.
#pragma once

#include <cstddef>
#include <cstdint>

#include "pliant/core/msm.hpp"

namespace pliant {

inline constexpr int kMaxOnlineAlphaRows = 8;
inline constexpr int kMaxOnlineStepRows = 4;            ///< 1, 2, 4, 8 MSM steps per frame
inline constexpr int kMaxEquilibriumIterations = 4096;  ///< per quasi-static candidate and frame

struct OnlineDeformabilityConfig {
  int candidates = 11;       ///< K >= 3 per alpha row, msm_beta = k / (K - 1)
  int alpha_candidates = 3;  ///< A in [1, kMaxOnlineAlphaRows]; 1: hold the base msm_alpha
  double alpha_min = 0.3;    ///< lowest msm_alpha row when A >= 2, in (0, 1)
  int step_candidates = 1;   ///< S in [1, kMaxOnlineStepRows]: rows at 1, 2, .., 2^(S-1) steps per frame
  double forgetting = 1.0;   ///< per-frame weight of past residuals, (0, 1]; 1 keeps everything
  /// The quasi-static row: 0 leaves it out; M in [1, kMaxEquilibriumIterations] adds K candidates
  /// relaxed towards equilibrium every frame with at most M MSM iterations each.
  int equilibrium_iterations = 0;
  double equilibrium_tolerance = 1e-4;  ///< relaxed when no particle moves more (x model spacing), > 0
};

struct OnlineDeformabilityEstimate {
  double msm_beta = 0;
  double msm_beta_std = 0;    ///< +inf until the curve has positive curvature
  double msm_alpha = 1;       ///< the answering form's msm_alpha (the base value when A = 1)
  bool alpha_fitted = false;  ///< the recording determined the form (see the header comment)
  int steps_per_frame = 1;    ///< the answering form's MSM steps per frame interval; 0: the quasi-static row
  bool unique_minimum = false;
  double rms = 0;            ///< rms residual of the answering row's best candidate, length unit
  std::uint32_t frames = 0;  ///< frames accepted so far
};

template <int Dim, typename Scalar>
struct OnlineDeformability {
  int candidates = 0;         ///< K, msm_beta values per row
  int alpha_candidates = 0;   ///< A, msm_alpha values per step count
  int step_candidates = 0;    ///< S, step counts
  bool quasi_static = false;  ///< the quasi-static row follows the A x S rows
  int equilibrium_iterations = 0;
  double equilibrium_tolerance = 0;  ///< length unit
  double alpha_min = 1;
  MsmParams<Dim, Scalar> params;  ///< base parameters; msm_beta (and msm_alpha when A >= 2) set per candidate
  /// [rows() x K]: row r < A x S = (steps r / A, alpha r % A), then the quasi-static row
  MsmState<Dim, Scalar>* states = nullptr;
  double* sum_squares = nullptr;                          ///< [rows() x K], forgetting applied
  Eigen::Matrix<Scalar, Dim, 1>* step_start = nullptr;    ///< [N] driven targets' interval start
  Eigen::Matrix<Scalar, Dim, 1>* step_targets = nullptr;  ///< [N] interpolated driven targets
  Eigen::Matrix<Scalar, Dim, 1>* previous = nullptr;      ///< [N] quasi-static row: the last iteration's positions
  double residual_count = 0;                              ///< scalar residuals, forgetting applied
  double forgetting = 1;
  std::uint32_t frames = 0;
  std::uint32_t rejected_frames = 0;  ///< bad dt, size mismatch
  std::uint32_t empty_frames = 0;     ///< frames with no free particle observed
  std::uint32_t unrelaxed = 0;        ///< quasi-static candidate frames that used every iteration
  bool initialized() const noexcept { return states != nullptr; }
  int stepped_rows() const noexcept { return alpha_candidates * step_candidates; }
  int rows() const noexcept { return stepped_rows() + (quasi_static ? 1 : 0); }
  int total_candidates() const noexcept { return candidates * rows(); }
  bool is_quasi_static(int row) const noexcept { return row >= stepped_rows(); }
  /// msm_alpha of row `row`: the base value when A = 1, else uniform on [alpha_min, 1]; 1 for the
  /// quasi-static row (an equilibrium does not depend on msm_alpha).
  double row_alpha(int row) const noexcept {
    if (is_quasi_static(row)) return 1.0;
    if (alpha_candidates <= 1) return static_cast<double>(params.msm_alpha);
    return alpha_min + (1.0 - alpha_min) * (row % alpha_candidates) / (alpha_candidates - 1);
  }
  /// MSM steps per frame interval of row `row`: 2^(row / A); 0 for the quasi-static row.
  int row_steps(int row) const noexcept { return is_quasi_static(row) ? 0 : 1 << (row / alpha_candidates); }
};

template <int Dim, typename Scalar>
std::size_t online_deformability_workspace_size(const MsmModel<Dim, Scalar>& model,
                                                const OnlineDeformabilityConfig& config) noexcept;

/// Carves the rows' states from `arena` and resets them to rest. `base` holds gravity, damping,
/// plasticity (and msm_alpha when A = 1) used by every candidate. invalid_argument for K < 3,
/// A outside [1, 8], S outside [1, 4], alpha_min outside (0, 1) with A >= 2, forgetting outside
/// (0, 1], equilibrium_iterations outside [0, kMaxEquilibriumIterations], or a tolerance not
/// finite and > 0 with the quasi-static row. Init time only.
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
