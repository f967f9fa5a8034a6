// Deformability estimation: the msm_beta (and optionally msm_alpha) that makes an MSM
// simulation reproduce observed trajectories (the optical-flow MSM paper, eq. 15).
//
// Modes
// - final_equilibrium (the paper): the driven particles are held at their final observed
//   positions and the model is relaxed to equilibrium (quasi-static: velocity zeroed each
//   iteration, same fixed point as the damped dynamics); error against the final frame.
// - trajectory: the model is stepped once per frame interval (the paper's time step) with the
//   driven particles following their observations; error over every frame.
// Error E(beta) = mean Euclidean distance between simulated and observed positions over the
// observed (frame, particle) pairs of free particles (neither fixed nor driven at that time);
// prescribed particles carry no information about beta and are left out.
//
// Search: E on a uniform grid over [0, 1], then Brent refinement (parabolic steps through the
// samples, golden-section steps where a parabola is unsafe) inside the best grid point's
// neighbours until the bracket is below `tolerance`; bounded by grid_points + max_refinements
// + 2 evaluations (x ~10 with estimate_alpha). Typically 5-7 refinement steps. Uncertainty:
// curvature of the sum of squared residuals at the minimum (curve_analysis.hpp), widened by the
// design effect of residuals that persist per particle over time (each particle's frames are one
// correlated cluster). In trajectory mode with Scalar = double the curvature is the second
// difference through the refinement's own samples next to the estimate (within tolerance / 2);
// in float, in the final mode (whose E is not smooth at that scale) or when such samples are
// missing, two more evaluations 0.01 either side give it. unique_minimum is false when the grid
// curve has a second basin, is flat, or the curvature is not positive.
//
// Real-time contract: the workspace is sized once (deformability_workspace_size) and carved
// at init; estimate_deformability allocates nothing and throws nothing. Its cost is bounded by
// evaluations x frames x one MSM step (trajectory) or x equilibrium_max_iterations (final).
#pragma once

#include <cstddef>
#include <cstdint>

#include "pliant/core/msm.hpp"
#include "pliant/core/observations.hpp"

namespace pliant {

enum class FitMode : std::uint8_t { final_equilibrium, trajectory };

/// Progress report: called after every error evaluation with the evaluations done and the
/// planned total (the total may grow by a few when refinement needs more). Must not block.
using ProgressCallback = void (*)(void* context, int done, int planned_total);

inline constexpr int max_steps_per_frame = 64;

struct DeformabilityConfig {
  FitMode mode = FitMode::trajectory;
  int grid_points = 11;     ///< >= 3, uniform over [0, 1]
  double tolerance = 1e-3;  ///< final bracket width on msm_beta
  int max_refinements = 40;
  bool estimate_alpha = false;  ///< also fit msm_alpha in [alpha_min, 1] (trajectory mode only)
  /// Trajectory mode: MSM steps per frame interval, each of interval / steps_per_frame, with the
  /// driven targets interpolated linearly between frames. 1..max_steps_per_frame.
  int steps_per_frame = 1;
  double alpha_min = 0.05;
  int equilibrium_max_iterations = 4000;
  double equilibrium_tolerance = 1e-5;  ///< largest move per iteration, x model spacing
  ProgressCallback progress = nullptr;  ///< optional
  void* progress_context = nullptr;
};

struct DeformabilityResult {
  double msm_beta = 0;
  double msm_alpha = 1;
  double msm_beta_std = 0;          ///< one standard deviation; +inf when not identifiable
  double residual_correlation = 0;  ///< share of residual variance persisting per particle (icc)
  double design_effect = 1;         ///< 1 + (m - 1) icc, m residuals per particle: variance inflation
  bool unique_minimum = false;
  double error = 0;         ///< E at the estimate (eq. 15), length unit
  double rms = 0;           ///< rms position residual at the estimate, length unit
  long residual_count = 0;  ///< observed (frame, particle) pairs compared
  int evaluations = 0;
  int frames_without_observations = 0;  ///< frames where no free particle was observed
  int unconverged_equilibria = 0;       ///< final mode: relaxations that hit their bound
  int curve_count = 0;                  ///< samples in the workspace curve, ascending msm_beta
};

template <int Dim, typename Scalar>
struct DeformabilityWorkspace {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  MsmState<Dim, Scalar> state;
  int driven_capacity = 0;
  int* target_ids = nullptr;                              ///< [driven_capacity]
  Vec* targets = nullptr;                                 ///< [driven_capacity]
  Vec* held = nullptr;                                    ///< [driven_capacity] last target per driven window
  Vec* interval_start = nullptr;                          ///< [driven_capacity] targets' previous-frame positions
  Vec* step_targets = nullptr;                            ///< [driven_capacity] targets within a frame interval
  std::uint8_t* window_active = nullptr;                  ///< [driven_capacity]
  Vec* previous = nullptr;                                ///< [particle_count] equilibrium convergence check
  Eigen::Matrix<double, Dim, 1>* residual_sum = nullptr;  ///< [particle_count] per-particle sums
  double* residual_samples = nullptr;                     ///< [particle_count]
  int curve_capacity = 0;
  double* curve_beta = nullptr;         ///< [curve_capacity] E(beta) samples of the last estimate
  double* curve_error = nullptr;        ///< [curve_capacity]
  double* curve_sum_squares = nullptr;  ///< [curve_capacity] sum of squared residuals per sample
  double* grid_error = nullptr;         ///< [grid_capacity] scratch: E on the uniform grid
  int grid_capacity = 0;
};

template <int Dim, typename Scalar>
std::size_t deformability_workspace_size(const MsmModel<Dim, Scalar>& model, int driven_capacity,
                                         const DeformabilityConfig& config) noexcept;

template <int Dim, typename Scalar>
[[nodiscard]] Status deformability_workspace_init(Arena& arena, const MsmModel<Dim, Scalar>& model, int driven_capacity,
                                                  const DeformabilityConfig& config,
                                                  DeformabilityWorkspace<Dim, Scalar>& workspace) noexcept;

/// Estimates msm_beta (and msm_alpha when asked) from `observations`. `base` supplies every
/// other model parameter (gravity, damping, plasticity; msm_alpha when not estimated).
/// Errors: invalid_argument (bad config, fewer than 2 frames, sizes that do not match the
/// model or workspace, times not increasing, driven ids not drivable), no_free_particles,
/// no_observations. A result with unconverged equilibria still returns ok; check the count.
template <int Dim, typename Scalar>
[[nodiscard]] Status estimate_deformability(const MsmModel<Dim, Scalar>& model, const MsmParams<Dim, Scalar>& base,
                                            const ObservationSequence<Dim, Scalar>& observations,
                                            const DeformabilityConfig& config,
                                            DeformabilityWorkspace<Dim, Scalar>& workspace,
                                            DeformabilityResult& result) noexcept;

/// Error of one parameter pair (for plots and tests): fills mean distance, rms and count.
struct TrajectoryError {
  double mean_distance = 0;
  double sum_squares = 0;
  long count = 0;
  double between_squares = 0;  ///< sum over particles of |sum of residuals|^2 / samples (trajectory)
  int compared_particles = 0;  ///< particles with at least one compared frame (trajectory)
  int frames_without_observations = 0;
  bool converged = true;
};
template <int Dim, typename Scalar>
[[nodiscard]] Status evaluate_deformability_error(const MsmModel<Dim, Scalar>& model,
                                                  const MsmParams<Dim, Scalar>& params,
                                                  const ObservationSequence<Dim, Scalar>& observations,
                                                  const DeformabilityConfig& config,
                                                  DeformabilityWorkspace<Dim, Scalar>& workspace,
                                                  TrajectoryError& error) noexcept;

}  // namespace pliant
