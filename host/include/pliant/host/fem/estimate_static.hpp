// Quasi-static material estimators on an FEM recording (fem_recording.hpp): Young's modulus from
// a measured wrench and tracked positions (force-driven, as STEPE: Sengupta et al., ICRA 2020),
// Young's modulus from a measured reaction force under prescribed displacements (indentation,
// compression tests), and remote estimation of the contact force from tracked deformation alone
// once the modulus is known.
//
// Model. Every selected frame is an independent static equilibrium of the corotational model
// (fem_solver.hpp, solve_static): inertia and damping are ignored, so the recording must be slow
// against the object's lowest natural period (a robot pressing and holding, a testing machine at
// 10 mm/min). Per frame: fixed nodes at rest, the frame's driven nodes at their prescribed
// positions, gravity as the problem's material says (zero unless the recording declared it).
// Young's modulus is one value for every element: a per-tetrahedron field in the mesh is replaced,
// not scaled. Poisson ratio, density and gravity are the problem's (known, not estimated).
//
// Optimisation. Every fit goes through fit_least_squares (Ceres Levenberg-Marquardt, bounds,
// robust loss with automatic scale by default, covariance). youngs_modulus is fitted on a log
// scale, so a start 10x too high costs as much as one 10x too low; contact forces and probe
// travels on a linear scale. Each residual evaluation re-solves the selected frames. Every frame
// keeps its last 8 solutions: a parameter value seen before (Ceres re-evaluates the current point,
// the covariance repeats the differences) is not solved again, and a new one starts from the
// affine prediction through the nearest ones (in compliance 1 / E, in which force-driven
// displacements are linear, or in the contact unknowns), so most solves take zero to two Newton
// iterations. Frames are independent, so they may be solved on several threads.
//
// Units SI: m, N, Pa, s. Forces are in the recording frame; a wrench's force is the force of the
// tool on the object, and its torque is about the centroid of the applied_to nodes' rest positions
// (docs/spec/recording-v1.md). After a static solve the solver's reaction at a constrained node is
// the force the constraint exerts on the body, so the tool's force on the object is the sum of
// reactions over the tool's nodes, directly comparable with the measured wrench.
//
// Whitening. Position residuals (simulated minus tracked, per coordinate, m) are divided by
// position_noise_m and force residuals (simulated minus measured, per axis, N) by force_noise_n.
// With a noise option left at 0 a provisional value is used for the fit (1 mm, 1 N) and the result
// reports the robust scatter (1.4826 x median |residual|) at the solution instead. With a single
// kind of residual the whitening does not move the estimate (the robust loss scale is automatic and
// the covariance is scaled by the residual scatter); it only sets what FitOptions::loss_scale and
// residual_sigma mean. It matters when positions and forces are mixed (reaction estimator with
// position_weight > 0): there, noise left at 0 is estimated from a force-only first fit.
//
// "Converged" in every result: the optimiser met a tolerance (not its iteration limit), every
// static solve at the reported solution converged, and the estimate is not at a bound.
//
// Host code: allocates, throws std::invalid_argument on an unusable problem (no frame selected,
// no residual, no wrench where one is needed) with a one-line message. Not real-time.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "pliant/host/fem/fem_recording.hpp"
#include "pliant/host/fem/fem_solver.hpp"
#include "pliant/host/least_squares_fit.hpp"

namespace pliant::host::fem {

/// Which frames of the recording enter an estimate. A frame is used when
/// first_time_s <= time_s <= last_time_s, it is the first, or a multiple of frame_stride after the
/// first, frame in that window, and (for the estimators that need one) it has a wrench sample.
struct FrameSelection {
  double first_time_s = -std::numeric_limits<double>::infinity();
  double last_time_s = std::numeric_limits<double>::infinity();
  int frame_stride = 1;  ///< >= 1
};

/// Fit settings for the modulus fits: FitOptions with the cost and step tolerances at 1e-8. The
/// static solves converge to about 1e-8 of the body's size, which leaves the cost a few 1e-8
/// relative of numerical noise; a tighter function tolerance only makes Levenberg-Marquardt grind
/// through rejected steps at the optimum (the estimate moves by < 1e-3 standard deviations).
/// No projected line search: the modulus is fitted on a log scale between bounds decades away
/// from a rescaled start, so its steps do not run into them, and the line search's gradient at
/// every trial point cost two thirds of the evaluations (STEPE case: 105 -> 31, the estimate the
/// same to 0.01 %).
inline FitOptions default_modulus_fit_options() {
  FitOptions fit;
  fit.function_tolerance = 1e-8;
  fit.parameter_tolerance = 1e-8;
  fit.projected_line_search = false;
  return fit;
}

/// Static solve settings for the estimators: the solver's defaults but at most 100 Newton
/// iterations (warm-started solves take a few; a solve that needs more is at a parameter value
/// where the model crushes under the measured load, and the evaluation is better rejected).
inline FemStaticOptions default_estimator_static_options() {
  FemStaticOptions options;
  options.max_iterations = 100;
  return options;
}

/// How a contact force is shared among the applied_to nodes.
enum class LoadSpread {
  /// Consistent nodal loads of a uniform traction over the boundary triangles whose three corners
  /// are all in applied_to (area / 3 per corner): a pressure-like load, independent of how the
  /// mesh is split; equal shares when applied_to spans no boundary triangle (a point or a line).
  uniform_traction,
  /// force / k on each of the k nodes (add_spread_force): the interior of a patch then carries
  /// less, its rim more than under a uniform pressure (+4 to +12 % on E on the STEPE block).
  equal_shares,
};

/// Options shared by the two Young's modulus estimators.
struct YoungsModulusOptions {
  FrameSelection frames;
  /// Force-driven estimator: how the measured force is shared among applied_to.
  LoadSpread load_spread = LoadSpread::uniform_traction;
  /// Start of the fit (Pa); 0: the problem's material value (recording's youngs_modulus if
  /// declared, else FemRecordingDefaults::youngs_modulus_pa).
  double initial_youngs_modulus_pa = 0;
  double lower_youngs_modulus_pa = 10;    ///< Pa, > 0, below the start
  double upper_youngs_modulus_pa = 1e11;  ///< Pa, above the start
  double position_noise_m = 0;            ///< per coordinate; 0: estimated (see Whitening above)
  double force_noise_n = 0;               ///< per axis; 0: estimated
  /// Fit settings. The default loss is Huber with automatic scale (robust to a few gross tracking
  /// outliers); use RobustLoss::cauchy for heavy outliers. difference_step is relative (log E).
  FitOptions fit = default_modulus_fit_options();
  /// Static solves. displacement_tolerance_m 0 means 1e-8 x the rest bounding-box diagonal here
  /// (tighter than the 1e-4 relative difference step needs, looser than the solver's own 1e-10);
  /// residual_tolerance_n 0 means 0.1 x E x mean edge length x that tolerance (the nodal force of
  /// such a displacement error), so a warm start that is already in equilibrium costs no
  /// factorization.
  FemStaticOptions static_options = default_estimator_static_options();
  /// Before the fit, rescale the start by the closed-form best scale: displacements go as 1 / E
  /// under force loading and reactions as E under prescribed displacements (exactly for linear
  /// elasticity), so one solve sequence at the start gives the least-squares optimal E of that
  /// linear model; repeated (at most 3 times) until it moves < 1 %, kept within 1e-3..1e3 x the
  /// start and the bounds. Levenberg-Marquardt then starts there, so a start 10x off costs a few
  /// evaluations instead of trust-region rejections of far overshooting steps (a Gauss-Newton step
  /// on log E from a 10x too stiff start overshoots by e^9). false: the fit starts at the start.
  bool rescale_start = true;
  /// Threads that solve frames in parallel (each with its own model copy and solvers), >= 1. The
  /// result depends on it only through warm starts, at the static solves' tolerance (~1e-8).
  int threads = 1;
  /// Keep every used frame's static solution at the estimate in StaticFrameRow::position_m
  /// (3n doubles per used frame).
  bool keep_frame_positions = false;
};

/// One row per used frame, at the solution.
struct StaticFrameRow {
  int frame = 0;  ///< index into FemRecordingProblem::frames
  double time_s = 0;
  /// Relative shortening of the distance between the centroid of applied_to and the centroid of
  /// the other constrained nodes (reaction estimator; NaN when not computable, 0 otherwise).
  double nominal_strain = 0;
  Eigen::Vector3d measured_force_n = Eigen::Vector3d::Zero();  ///< the wrench (tool on object)
  /// Force estimator: the force applied (= measured). Reaction estimator: the simulated tool force
  /// (sum of reactions over the reaction nodes, plus the fitted offset if any).
  Eigen::Vector3d simulated_force_n = Eigen::Vector3d::Zero();
  int position_count = 0;                                            ///< tracked free nodes compared in this frame
  double position_rms_m = std::numeric_limits<double>::quiet_NaN();  ///< rms |sim - tracked| (3D)
  int newton_iterations = 0;  ///< of the static solve that produced this solution
  /// The static solution itself (3n node positions, m), only with
  /// YoungsModulusOptions::keep_frame_positions (empty otherwise): for residual maps and
  /// visualisation of the fitted model.
  Eigen::VectorXd position_m;
};

struct YoungsModulusEstimate {
  bool converged = false;  ///< see "Converged" above
  double youngs_modulus_pa = 0;
  double standard_deviation_pa = std::numeric_limits<double>::quiet_NaN();  ///< 1 sigma, from the fit
  double initial_youngs_modulus_pa = 0;
  double rescaled_start_pa = 0;  ///< where the optimiser started (= initial without rescale_start)
  double position_noise_m = std::numeric_limits<double>::quiet_NaN();  ///< whitening used or estimated
  double force_noise_n = std::numeric_limits<double>::quiet_NaN();     ///< whitening used or estimated
  double position_rms_m = std::numeric_limits<double>::quiet_NaN();    ///< over every compared coordinate x3
  double force_rms_n = std::numeric_limits<double>::quiet_NaN();       ///< per fitted axis, reaction fit
  Eigen::Vector3d force_offset_n = Eigen::Vector3d::Zero();            ///< reaction fit with fit_force_offset
  double residual_sigma = 0;  ///< FitResult::residual_sigma (about 1 when whitening is right)
  int residual_count = 0;
  int frames_used = 0;
  int iterations = 0;   ///< optimiser iterations over all passes (and stages)
  int evaluations = 0;  ///< solve sequences: fit evaluations, start rescaling, final table
  long static_solves = 0;
  long newton_iterations = 0;  ///< over every static solve
  double wall_s = 0;
  double cpu_s = 0;  ///< process CPU time (all threads)
  std::vector<StaticFrameRow> frames;
  FitResult fit;        ///< the (last stage's) optimiser result
  std::string message;  ///< one line: what was fitted, to which data, the outcome
};

/// (a) Force-driven, as STEPE. Per used frame (frames with a wrench), the measured wrench is
/// applied as nodal load on applied_to (the force shared as options.load_spread says, plus the
/// least-squares forces of add_spread_wrench carrying the torque about the nodes' rest centroid;
/// the load keeps its direction as the body deforms); fixed nodes are fixed and the frame's
/// driven nodes prescribed.
/// Residuals: simulated minus tracked position, per coordinate, of every observed node that is
/// neither fixed nor driven in that frame, whitened by position_noise_m. Needs a wrench and at
/// least one such observation. Cost: (evaluations) x (used frames) warm-started static solves.
YoungsModulusEstimate estimate_youngs_modulus_from_force(const FemRecordingProblem& problem,
                                                         const YoungsModulusOptions& options = {});

struct ReactionEstimateOptions : YoungsModulusOptions {
  /// Frames are used from the first while the nominal strain (StaticFrameRow::nominal_strain)
  /// stays <= this; the first frame exceeding it ends the selection. Infinity: off.
  double max_nominal_strain = std::numeric_limits<double>::infinity();
  /// Weight of the position residuals of tracked free nodes relative to the force residuals
  /// (multiplies their whitened squares); 0: forces only.
  double position_weight = 0;
  /// Also fit a constant force offset per fitted axis (bounded by the largest measured force):
  /// simulated + offset is compared with the measurement. Toe compensation: compression and
  /// indentation curves usually start softer than their linear part (platen seating, surface
  /// roughness, load-cell zero), and a line through the origin then underestimates the modulus
  /// of the linear part. Reported in YoungsModulusEstimate::force_offset_n.
  bool fit_force_offset = false;
};

/// (b) Displacement-driven with a measured reaction (indentation and compression tests). Per used
/// frame the driven nodes are prescribed and the tool force is the sum of the solver's reactions
/// over the reaction nodes: applied_to's constrained nodes (fixed or driven in that frame), or,
/// when none of applied_to is constrained, the frame's driven nodes. Residuals: simulated minus
/// measured force on every axis whose measured component somewhere exceeds 1 % of the largest
/// measured force norm (axes that read zero throughout, e.g. fx and fy of a uniaxial test, carry no
/// information and are left out), whitened by force_noise_n; plus, with position_weight > 0, the
/// position residuals of estimate_youngs_modulus_from_force. Without gravity and external loads
/// the displacement field does not depend on E and the reaction is proportional to it.
YoungsModulusEstimate estimate_youngs_modulus_from_reaction(const FemRecordingProblem& problem,
                                                            const ReactionEstimateOptions& options = {});

/// Fit settings for contact forces: as default_modulus_fit_options (with the projected line
/// search) but with a difference step of
/// 1e-5 of the parameter range (2 x the bound): about 1 N for forces on the STEPE block, 7 um for
/// the probe's travel; large against the static solves' tolerance, small against the nonlinearity.
inline FitOptions default_contact_force_fit_options() {
  FitOptions fit = default_modulus_fit_options();
  fit.difference_step = 1e-5;
  fit.projected_line_search = true;  // three linear unknowns whose bounds can be reached
  return fit;
}

/// How the unknown contact acts on the model.
enum class ContactModel {
  /// STEPE's: a force vector F spread over the applied_to nodes (load_spread: a uniform traction
  /// by default, or equal shares), keeping its direction. Unknowns: F (N). Suits soft or padded
  /// contacts; against a rigid flat probe pressed deep it underestimates (see the bench).
  spread_force,
  /// A rigid probe bonded to the applied_to nodes: they translate together by an unknown vector u
  /// (m, from rest) and the force is the sum of their reactions (tool on object). Suits a robot's
  /// rigid tool; uses no robot odometry.
  rigid_probe,
};

struct ContactForceOptions {
  ContactModel contact = ContactModel::spread_force;
  LoadSpread load_spread = LoadSpread::uniform_traction;  ///< spread_force: how F is shared
  FrameSelection frames;                                  ///< frames without a wrench are estimated too (no comparison)
  /// spread_force: bound on each force component (N); 0: E x L^2 with L the rest bounding-box
  /// diagonal (a force that would deform the whole body by about its own size).
  double force_bound_n = 0;
  /// rigid_probe: bound on each component of the probe's travel (m); 0: L.
  double probe_travel_bound_m = 0;
  double position_noise_m = 0;  ///< per coordinate; 0: estimated (see Whitening above)
  FitOptions fit = default_contact_force_fit_options();
  FemStaticOptions static_options = default_estimator_static_options();  ///< as for the modulus fits
  int threads = 1;  ///< frames in parallel: contiguous blocks, each warm-started in time order
};

/// One row per used frame.
struct ContactForceFrame {
  int frame = 0;
  double time_s = 0;
  bool converged = false;
  Eigen::Vector3d estimated_force_n = Eigen::Vector3d::Zero();  ///< force on the object
  /// 1 sigma per component from the fit (rigid_probe: propagated through dF/du).
  Eigen::Vector3d standard_deviation_n = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  /// rigid_probe: the probe's estimated travel from rest (m); NaN for spread_force.
  Eigen::Vector3d probe_displacement_m = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  bool has_measurement = false;
  Eigen::Vector3d measured_force_n = Eigen::Vector3d::Zero();
  /// STEPE Table III: the estimate projected onto the measured direction, est . m / |m| (N), and
  /// its difference from |m|. NaN without a measurement or with |m| = 0.
  double projected_force_n = std::numeric_limits<double>::quiet_NaN();
  double projected_difference_n = std::numeric_limits<double>::quiet_NaN();
  double relative_error = std::numeric_limits<double>::quiet_NaN();  ///< |est - m| / |m|
  int position_count = 0;
  double position_rms_m = std::numeric_limits<double>::quiet_NaN();
  int iterations = 0;
  int evaluations = 0;
};

struct ContactForceEstimate {
  bool converged = false;  ///< every frame's fit converged (none at a bound)
  ContactModel contact = ContactModel::spread_force;
  double youngs_modulus_pa = 0;
  double position_noise_m = std::numeric_limits<double>::quiet_NaN();  ///< whitening used or estimated
  std::vector<ContactForceFrame> frames;
  /// Means over frames with a measurement of nonzero norm (Table III: f_GT, f_est, and
  /// Delta f = mean projected - mean measured).
  int compared_frames = 0;
  double mean_measured_norm_n = std::numeric_limits<double>::quiet_NaN();
  double mean_estimated_norm_n = std::numeric_limits<double>::quiet_NaN();
  double mean_projected_n = std::numeric_limits<double>::quiet_NaN();
  double mean_difference_n = std::numeric_limits<double>::quiet_NaN();
  double mean_relative_error = std::numeric_limits<double>::quiet_NaN();
  int evaluations = 0;
  long static_solves = 0;
  double wall_s = 0;
  double cpu_s = 0;
};

/// (f) Remote force estimation (STEPE Sec. II-C). With Young's modulus known, per used frame the
/// contact (options.contact: a force spread over applied_to, or a rigid probe's translation; three
/// unknowns either way) whose static solution best matches the tracked positions of the observed
/// nodes that are neither fixed nor driven in the recording (whitened by position_noise_m). The
/// measured wrench is not used by the fit, only compared with. Frames are fitted in time order,
/// each started from the previous frame's estimate (zero for the first). Needs applied_to (the
/// recording's wrench.applied_to names the contact region) and tracked free nodes. Cost per frame:
/// roughly 50-300 warm-started static solves (7 per iteration: 3 unknowns, central differences,
/// robust passes), few of them needing more than one Newton iteration.
ContactForceEstimate estimate_contact_force(const FemRecordingProblem& problem, double youngs_modulus_pa,
                                            const ContactForceOptions& options = {});

/// Plain-text tables for reports and tests (one line per frame, fixed-width columns).
std::string format_frame_table(const YoungsModulusEstimate& estimate);
std::string format_frame_table(const ContactForceEstimate& estimate);

}  // namespace pliant::host::fem
