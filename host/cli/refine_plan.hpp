// `pliant refine`: what to estimate and with which FEM estimator, decided from the command line
// and from what the recording contains, before any simulation runs.
//
// Estimators (host/include/pliant/host/fem/):
//  * force      estimate_youngs_modulus_from_force: the measured wrench is applied to free
//               particles (wrench.applied_to neither fixed nor driven) and the tracked free
//               particles are matched, frame by frame, as static equilibria (STEPE).
//  * reaction   estimate_youngs_modulus_from_reaction: driven (or fixed) particles carry the
//               wrench, which is the reaction of a prescribed displacement (compression and
//               indentation tests); the simulated reaction is matched, frame by frame, statically.
//  * trajectory estimate_trajectory_parameters: the whole recording is simulated (Newmark) from
//               frame 0 and the tracked free particles are matched in every frame; free motion
//               such as a vibration after release. The only one that sees damping and the only
//               one with material maps.
// Rest shape (estimate_rest_shape) is separate: it runs after the material fit, if any.
//
// Every refusal is a UsageError (exit status 2) with one line saying why.
#pragma once

#include <optional>
#include <string>

#include "pliant/host/fem/fem_recording.hpp"

namespace pliant::cli {

enum class RefineEstimator { force, reaction, trajectory };

/// "force", "reaction", "trajectory".
const char* to_string(RefineEstimator estimator);

/// The names given to --estimate, resolved. `rayleigh` sets both coefficients.
struct RefineRequest {
  bool given = false;  ///< --estimate was on the command line (else the defaults apply)
  bool youngs_modulus = false;
  bool rayleigh_alpha = false;
  bool rayleigh_beta = false;
  bool material_map = false;
  bool rest_shape = false;
};

/// Parses "youngs_modulus,rayleigh,..." (names: youngs_modulus, rayleigh, rayleigh_alpha,
/// rayleigh_beta, material_map, rest_shape; spaces around names ignored). Throws UsageError on
/// an unknown or empty name.
RefineRequest parse_estimate_list(const std::string& text);

/// What will run.
struct RefinePlan {
  bool youngs_modulus = false;  ///< one value, or one per control point with material_map
  bool material_map = false;
  bool rayleigh_alpha = false;
  bool rayleigh_beta = false;
  bool rest_shape = false;
  /// The material estimator; empty when only the rest shape is estimated.
  std::optional<RefineEstimator> estimator;
  std::string reason;  ///< why this estimator (a phrase for the summary)
  bool fits_material() const { return youngs_modulus || rayleigh_alpha || rayleigh_beta; }
};

/// Decides the plan. `estimator_choice` is "auto", "force", "reaction" or "trajectory".
/// Defaults (request.given false): youngs_modulus, plus rayleigh_alpha and rayleigh_beta when
/// the estimator is the trajectory one; parameters recording.json already gives are left out.
/// Throws UsageError for an unknown choice, a parameter the recording already gives, nothing
/// left to estimate, or a combination the recording cannot support (the message says why).
RefinePlan plan_refine(const host::fem::FemRecordingProblem& problem, const RefineRequest& request,
                       const std::string& estimator_choice);

/// Refuses a rest-shape estimate the recording cannot support (UsageError, one line): `frame` out
/// of range, not every mesh point observed in it, a driven particle in it, no gravity declared,
/// density not given, or Young's modulus neither given nor estimated in this run.
void check_rest_shape(const host::fem::FemRecordingProblem& problem, const RefinePlan& plan, int frame);

}  // namespace pliant::cli
