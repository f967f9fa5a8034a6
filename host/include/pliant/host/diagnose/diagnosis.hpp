// Result of `pliant diagnose` (docs/spec/diagnosis-v1.md) and the evidence behind it.
//
// Diagnosis holds exactly what the pliant-diagnosis v1 JSON carries; DiagnosisEvidence holds
// the arrays the HTML report plots. Units: positions and rms in the recording's length_unit,
// times in seconds. Host code: plain data, no behaviour.
#pragma once

#include <limits>
#include <map>
#include <string>
#include <vector>

namespace pliant::host {

/// A fitted model: parameter name -> value (names from recording-v1 "Parameter names" plus the
/// effect parameters), with one standard deviation per parameter where known.
struct FittedModel {
  std::string model = "msm";                    ///< "msm" or "fem"
  std::map<std::string, double> parameters;     ///< e.g. {"msm_alpha": 1, "msm_beta": 0.58}
  std::map<std::string, double> parameter_std;  ///< same keys (subset); absent: not computed
  double rms = 0;                               ///< held-out output-error rms, length_unit
  /// FEM with a measured wrench: held-out rms of the force residual (N); NaN otherwise (then
  /// absent from the JSON). `rms` is NaN (JSON null) when no free node position is compared.
  double force_rms = std::numeric_limits<double>::quiet_NaN();
  /// MSM only (0 otherwise): the model form the baseline selection chose, which is not physics:
  /// MSM steps per frame interval, msm_alpha fitted (else held), and why (one sentence).
  int steps_per_frame = 0;
  bool alpha_fitted = false;
  double cluster_radius_factor = 0;  ///< cluster radius / median nearest-neighbour distance
  std::string form_reason;
};

struct Candidate {
  std::string effect;                        ///< a word of the spec's effect table
  std::map<std::string, double> parameters;  ///< effect parameters only (and refitted msm_beta)
  std::map<std::string, double> parameter_std;
  double rms = 0;  ///< held-out rms
  double bic = 0;  ///< Bayesian information criterion on the fitting frames (lower is better)
  /// MSM: share of the baseline's held-out misfit beyond the noise that the effect removes,
  /// 1 - (rms^2 - noise^2) / (baseline rms^2 - noise^2); NaN (absent from the JSON) otherwise.
  double explained = std::numeric_limits<double>::quiet_NaN();
  double force_rms = std::numeric_limits<double>::quiet_NaN();  ///< held-out force rms (N), FEM only
};

struct Location {
  std::vector<int> particles;  ///< ids where the baseline residual concentrates (ascending)
  double t_start = 0;
  double t_end = 0;
};

struct Diagnosis {
  std::string recording;  ///< recording name
  FittedModel baseline;
  double noise_rms = 0;
  /// FEM with a measured wrench: the force noise rms (N) of the wrench stream (per-component std
  /// times sqrt(3)); NaN otherwise (absent from the JSON).
  double force_noise_rms = std::numeric_limits<double>::quiet_NaN();
  std::string verdict = "consistent";  ///< "consistent" or "missing_physics"
  std::string effect = "none";
  std::string explanation;
  Location location;
  FittedModel augmented;  ///< equals baseline when consistent
  /// 1 - augmented.rms / baseline.rms (held-out frames). FEM: the same ratio of the held-out rms
  /// of the whitened residuals (positions / position noise and forces / force noise together),
  /// which is the position ratio without a measured force and the force_rms ratio without
  /// compared positions.
  double improvement = 0;
  std::vector<Candidate> candidates;  ///< best first
  /// MSM: share of block-bootstrap resamples of the held-out frames in which the best passing
  /// effect still improves the fit enough to be named (NaN when no effect passed).
  double selection_stability = std::numeric_limits<double>::quiet_NaN();
  /// An effect that fits almost as well as the named one (or wins on a fifth of the resamples);
  /// empty when none. The explanation names the experiment that separates them.
  std::string runner_up;
};

/// Per-frame, per-particle arrays for the report. A residual map is frame-major:
/// map[frame * particle_count + id] = |observed - simulated| (length_unit), NaN where the
/// particle is unobserved in that frame.
struct DiagnosisEvidence {
  int dimension = 2;
  int particle_count = 0;
  std::string length_unit = "m";
  std::vector<double> frame_times_s;
  std::vector<unsigned char> held_out;     ///< [frames] 1 where the frame was held out of fitting
  std::vector<double> residual_baseline;   ///< [frames * particle_count]
  std::vector<double> residual_augmented;  ///< [frames * particle_count]; equals baseline when consistent
  /// Trajectories, frame-major [frames * particle_count * dimension], NaN where unobserved.
  std::vector<double> observed;
  std::vector<double> simulated_baseline;
  std::vector<double> simulated_augmented;
  std::vector<int> fixed;   ///< declared fixed ids
  std::vector<int> driven;  ///< ids driven at some time
  /// Named signature statistics from the locate step (e.g. "persistence_after_unload": 0.8),
  /// shown in the report's evidence table.
  std::map<std::string, double> signatures;
  /// FEM with a measured wrench: the force per frame [frame * 3 + axis] (N), NaN where not
  /// compared; empty otherwise.
  std::vector<double> force_observed;
  std::vector<double> force_baseline;
  std::vector<double> force_augmented;
};

}  // namespace pliant::host
