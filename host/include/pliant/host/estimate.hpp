// msm_beta estimation of a whole recording (host side of `pliant estimate`).
//
// Builds the MSM model from the recording (msm_setup.hpp), runs the core estimator in double
// precision and returns the result with its error curve. estimate_json() renders the
// `pliant-estimate` v1 document (docs/spec/outputs-v1.md). Host code: allocates, throws
// std::runtime_error with a one-line message when the recording cannot be estimated.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pliant/core/deformability.hpp"
#include "pliant/host/msm_setup.hpp"
#include "pliant/host/recording.hpp"

namespace pliant::host {

/// How msm_alpha (the shape-matching relaxation) is treated.
/// - automatic: msm_beta is fitted with msm_alpha held at `msm_alpha` and together with msm_alpha;
///   the joint fit is kept when the recording determines msm_alpha (the baseline selection below).
///   The final-equilibrium mode does not depend on msm_alpha and always holds it.
/// - fitted: msm_beta and msm_alpha together (trajectory mode only).
/// - fixed: msm_alpha held at `msm_alpha` (the behaviour before automatic was the default).
enum class AlphaMode : std::uint8_t { automatic, fitted, fixed };

/// Largest MSM steps per frame interval the automatic choice tries first; when that many win, it
/// doubles them while the doubled count keeps winning, up to max_steps_per_frame.
inline constexpr int max_auto_steps_per_frame = 4;

/// Cluster radii (times the median nearest-neighbour distance of the rest shape) the automatic
/// choice tries first besides the setup's own (1.5 by default), then the radii between them at
/// which the clusters change (cluster_radii.hpp). They lie between the distances of square and
/// hexagonal lattices (1, sqrt 2, sqrt 3, 2, sqrt 5, sqrt 6; and 1, sqrt 3, 2, sqrt 7 spacings),
/// so on a lattice with a noisy rest shape each takes in whole shells of neighbours and the
/// search between them finds nothing more to fit.
inline constexpr double auto_cluster_radii[] = {1.3, 1.85, 2.1, 2.3};

struct EstimateOptions {
  FitMode mode = FitMode::trajectory;
  AlphaMode alpha = AlphaMode::automatic;
  double msm_alpha = 1.0;  ///< in (0, 1]: the held value (fixed, and the alternative automatic weighs)
  /// Trajectory mode: MSM steps per frame interval. 0 = chosen by the baseline selection among
  /// 1..max_auto_steps_per_frame (and doubled counts beyond, see above); else held at that value
  /// (1..max_steps_per_frame).
  int steps_per_frame = 0;
  /// Trajectory mode, radius cluster layout: also try auto_cluster_radii and keep the best (BIC);
  /// false holds setup.clusters.radius_factor.
  bool cluster_radius_auto = true;
  int grid_points = 11;
  double tolerance = 1e-3;
  MsmSetupOptions setup;
  /// Refits with the rest shape and the tool track perturbed by the measured position noise,
  /// this many times; their spread is the part of the uncertainty that input noise causes
  /// (the curvature of the error curve only sees noise on the compared particles). 0: off.
  int input_noise_samples = 8;
  ProgressCallback progress = nullptr;  ///< forwarded to DeformabilityConfig; must not block
  void* progress_context = nullptr;
};

/// One variant of the baseline model that was fitted: steps per frame and msm_alpha held or fitted.
struct BaselineCandidate {
  int steps_per_frame = 1;
  bool alpha_fitted = false;
  double msm_alpha = 1;
  double msm_beta = 0;
  double rms = 0;  ///< rms position residual per coordinate, length unit
  double bic = 0;  ///< Bayesian information criterion over the effective residuals (lower is better)
  double cluster_radius_factor = 1.5;  ///< cluster radius / median nearest-neighbour distance
};

/// How the baseline was chosen: every variant fitted, the one kept, and why (docs/estimation.md).
struct BaselineChoice {
  std::vector<BaselineCandidate> candidates;  ///< in the order fitted
  int chosen = 0;                             ///< index into candidates
  double effective_residuals = 0;             ///< residual scalars / design effect of the best-fitting variant
  std::string reason;                         ///< one sentence for people
  bool alpha_fitted() const {
    return candidates.empty() ? false : candidates[static_cast<std::size_t>(chosen)].alpha_fitted;
  }
  int steps_per_frame() const {
    return candidates.empty() ? 1 : candidates[static_cast<std::size_t>(chosen)].steps_per_frame;
  }
  /// The kept variant's cluster radius factor; `fallback` when nothing was fitted.
  double cluster_radius_factor(double fallback) const {
    return candidates.empty() ? fallback : candidates[static_cast<std::size_t>(chosen)].cluster_radius_factor;
  }
  /// The candidates' msm_beta spread (one sd) around the kept one's, each candidate weighted by
  /// exp(-(bic - bic_kept) / 2); 0 with fewer than two candidates (docs/estimation.md).
  double msm_beta_spread() const;
};

/// Human-readable name of a mode ("auto", "fit", "fixed").
const char* alpha_mode_name(AlphaMode mode);

/// The command-line form: "auto", "fit" (also ""), "fixed" (held at 1) or "fixed=A" with A in
/// (0, 1]. Sets `mode` and, for fixed, `held_alpha`; throws std::invalid_argument naming the text.
void parse_alpha_choice(const std::string& text, AlphaMode& mode, double& held_alpha);

struct EstimateReport {
  DeformabilityResult result;
  BaselineChoice baseline;
  std::vector<double> curve_beta;
  std::vector<double> curve_error;
  int cluster_count = 0;
  double cluster_radius_factor = 1.5;  ///< of the kept variant (radius layout)
  int rest_frames = 1;                 ///< leading still frames averaged into the rest shape
  double noise_std = 0;                ///< position noise used for the input perturbation
  double msm_beta_std_curvature = 0;   ///< from the error curve alone (core estimator)
  double msm_beta_std_input = 0;       ///< spread of refits under perturbed inputs
  /// Spread of msm_beta over the baseline variants fitted (steps per frame, msm_alpha held or
  /// fitted, cluster radius), each weighted by exp(-(BIC - BIC_kept) / 2), around the kept one's
  /// value: near-ties between forms that read msm_beta differently widen the uncertainty.
  double msm_beta_std_model_form = 0;
  double msm_beta_std = 0;      ///< combined: sqrt(curvature^2 + input^2 + model_form^2)
  double spacing = 0;           ///< median nearest-neighbour distance of the rest shape
  double frame_interval_s = 0;  ///< mean time step used by the simulation
  double runtime_s = 0;
};

/// Throws std::runtime_error naming the problem (e.g. "every particle is fixed or driven").
EstimateReport estimate_recording(const Recording& recording, const EstimateOptions& options);

/// The outputs-v1 `pliant-estimate` document for a report.
nlohmann::json estimate_json(const Recording& recording, const EstimateOptions& options, const EstimateReport& report);

/// "final" / "trajectory" and back; parse throws std::invalid_argument on anything else.
const char* fit_mode_name(FitMode mode);
FitMode parse_fit_mode(const std::string& name);

}  // namespace pliant::host
