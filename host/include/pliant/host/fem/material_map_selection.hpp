// How many material control points a recording supports (issue 17 item 4): the trajectory
// estimator (estimate_dynamic.hpp) is run with 1, 2, 4, ... control points placed by
// place_control_points (material_map.hpp), and the count with the lowest Bayesian information
// criterion is kept. A user who does not know how the material varies gets as many control
// points as the data determine, not a fixed number.
//
// The criterion. For a fit with p unknowns (the control moduli plus the Rayleigh coefficients
// fitted) leaving the residual sum of squares S over n residual coordinates,
//     BIC = n_eff ln(S / n) + p ln(n_eff),    n_eff = n / d,
// where d is the design effect of residuals correlated in time: a track's residual in one frame
// is mostly its residual in the previous one (a misfit of the model's form persists, and so does
// a phase error), so the n coordinates hold fewer independent samples. d = (1 + rho) / (1 - rho)
// with rho the lag-1 autocorrelation of the residual series over frames, pooled over every
// observed free coordinate (rho clamped to [0, 0.98]); the value of the best-fitting candidate
// so far is used for every candidate, so that they are compared on one scale.
//
// The search. Counts are tried in ascending order, each fit continued from the best map so far
// (its field at the new control points and its Rayleigh coefficients as the start, no modal warm
// start), so that a finer map starts no worse than the coarser one; on the 8-slab bar a 2-point
// fit from the uniform warm start ended ten times worse than the uniform fit. The search stops
// after `patience` counts in a row whose BIC is not lower than the best so far, or when a count
// exceeds the number of tetrahedra (none left: std::invalid_argument). The chosen fit is returned
// whole.
//
// Undetermined regions. A control point of the chosen map whose modulus has no finite standard
// deviation, or one larger than undetermined_relative_sd times its value, is listed in
// `undetermined`: the data do not say what the material is there (too little motion, too few
// observed nodes near it). Its value is the fit's, and should not be relied on.
//
// Units SI (m, Pa). Host code: allocates, throws what estimate_trajectory_parameters throws, and
// std::invalid_argument for bad options. Cost: one trajectory fit per count tried, plus one
// simulation each for the residual series.
#pragma once

#include <vector>

#include "pliant/host/fem/estimate_dynamic.hpp"
#include "pliant/host/fem/fem_recording.hpp"

namespace pliant::host::fem {

struct MaterialMapSelectionOptions {
  /// Control-point counts to try, ascending, each >= 1.
  std::vector<int> counts = {1, 2, 4, 8, 16, 32};
  /// Stop after this many counts in a row that do not lower the BIC (>= 1).
  int patience = 1;
  /// A control modulus whose sd exceeds this fraction of its value is undetermined (> 0).
  double undetermined_relative_sd = 0.5;
};

/// One count tried.
struct MaterialMapCandidate {
  int control_points = 0;
  int parameters = 0;  ///< fitted unknowns
  int residual_count = 0;
  double residual_rms_m = 0;    ///< per coordinate
  double lag1_correlation = 0;  ///< of its residual series over frames (pooled)
  double bic = 0;               ///< with the design effect of the best-fitting candidate (see above)
  bool converged = false;
  double cpu_time_s = 0;
};

struct MaterialMapSelection {
  std::vector<MaterialMapCandidate> candidates;  ///< in the order tried
  int chosen = 0;                                ///< index into candidates
  double design_effect = 1;                      ///< d used for every BIC
  TrajectoryEstimate estimate;                   ///< the chosen count's fit
  std::vector<int> undetermined;                 ///< control points of the chosen map (indices)
};

/// Selects the number of control points (see the file comment). fit_options are used for every
/// fit; their control_points_m are replaced by place_control_points(problem.mesh, k).
MaterialMapSelection select_material_map(const FemRecordingProblem& problem,
                                         const TrajectoryEstimateOptions& fit_options = {},
                                         const MaterialMapSelectionOptions& options = {});

}  // namespace pliant::host::fem
