// `pliant refine`: runs the planned estimators (refine_plan.hpp) on an FEM recording problem and
// collects what the material card, the summary and the VTK series need.
//
// Order: the material fit (force, reaction or trajectory estimator), then the rest shape, which
// uses the fitted Young's modulus (or map) when the recording does not give one.
//
// The fitted model's positions ("simulated frames"), from which the card's rms comes and which
// --vtk writes:
//  * force, reaction: the static equilibrium at the estimate in every frame the fit used (frames
//    with a wrench; reaction: up to the strain limit);
//  * trajectory: one simulation of the whole recording at the estimate (every frame);
//  * rest shape alone: the static shape the estimated rest shape settles into under gravity, at
//    the rest frame.
// rms = sqrt(mean |x_model - x_observed|^2) over every observed (particle, frame) pair of those
// frames, in metres: fixed and driven particles count with the positions the model gives them
// (their rest or prescribed positions), so a test that observes only its driven platens has rms 0
// (its fit is judged by the force residual). free_rms is the same over particles that are
// neither fixed nor driven in that frame.
//
// Units SI (m, s, Pa, N). Host code: allocates, throws (estimator errors pass through).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "pliant/host/fem/estimate_rest_shape.hpp"
#include "pliant/host/fem/fem_recording.hpp"
#include "refine_plan.hpp"
#include "refine_progress.hpp"

namespace pliant::cli {

/// Estimator settings from the command line (command_refine.cpp documents each flag).
struct RefineSettings {
  double max_strain = 0.10;                       ///< reaction: frames up to this nominal strain; >= 1: all
  bool force_offset = true;                       ///< reaction: fit a constant force offset (toe)
  double initial_youngs_modulus_pa = 0;           ///< start; 0: recording's value or 1e5 Pa
  bool select_control_points = true;              ///< material_map: the count chosen by the data
  int control_point_count = 4;                    ///< material_map: placed by place_control_points
  std::vector<Eigen::Vector3d> control_points_m;  ///< material_map: given (overrides the count)
  int rest_frame = 0;                             ///< rest_shape: the static frame
  int threads = 1;                                ///< >= 1
  int substeps = 4;                               ///< trajectory: Newmark substeps per frame interval
  /// trajectory: the tracks' measured noise per coordinate (m, noise_floor.hpp); the fit's
  /// whitening and its test of whether the warm start already explains the data. 0 (noise-free
  /// or unmeasurable tracks): the estimator's default whitening, and no stopping at the start.
  double position_noise_m = 0;
};

/// The fitted model at one frame.
struct SimulatedFrame {
  int frame = 0;               ///< index into FemRecordingProblem::frames
  Eigen::VectorXd position_m;  ///< 3n
};

struct RefineOutcome {
  /// Estimated parameters (card "parameters" and "uncertainty"), by recording-v1 name.
  std::map<std::string, double> estimated;
  std::map<std::string, double> uncertainty;  ///< 1 sd; NaN when the data do not determine it
  /// Values the model used that the recording does not give and refine did not estimate.
  std::map<std::string, double> assumed;

  /// Said to the user after the run (e.g. control points the data do not determine).
  std::vector<std::string> warnings;

  bool has_map = false;
  std::vector<Eigen::Vector3d> control_points_m;
  std::vector<double> control_youngs_modulus_pa;
  std::vector<double> control_youngs_modulus_sd_pa;
  double kernel_width_m = 0;

  /// Young's modulus per tetrahedron of the fitted model (Pa); empty when not known.
  Eigen::VectorXd element_youngs_modulus_pa;

  std::optional<host::fem::RestShapeResult> rest_shape;

  std::vector<SimulatedFrame> simulated;
  Eigen::VectorXd simulated_rest_m;  ///< the rest shape the simulated frames deform from (3n)
  double rms_m = 0;
  long rms_pairs = 0;
  double free_rms_m = 0;  ///< NaN when no free particle is observed in those frames
  long free_rms_pairs = 0;

  bool converged = true;    ///< every fit converged (see diagnostics)
  std::string fit_message;  ///< the material estimator's one-line outcome (empty without one)
  nlohmann::json diagnostics = nlohmann::json::object();
};

/// Runs the plan. progress gets the stages and the optimiser's iterations.
RefineOutcome run_refine(const host::fem::FemRecordingProblem& problem, const RefinePlan& plan,
                         const RefineSettings& settings, RefineProgress& progress);

}  // namespace pliant::cli
