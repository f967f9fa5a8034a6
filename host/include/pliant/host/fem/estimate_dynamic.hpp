// Young's modulus (one value or a material map) and Rayleigh damping from a recorded trajectory,
// after Wang et al., "Deformation capture and modeling of soft objects" (space-time estimation
// with a modal warm start): simulate the whole recording with the corotational FEM and fit the
// parameters so that the simulated node positions match the observed ones in every frame.
//
// Forward model (one residual evaluation = one simulation of the whole recording):
//  * initial positions: frame 0's observations; free nodes unobserved in frame 0 (the interior,
//    when only the surface is tracked) are put at static equilibrium with the observed and
//    constrained nodes held (recomputed for every parameter set). Exact for a body released from
//    rest under loads applied at observed nodes, the usual free-vibration experiment.
//  * initial velocity: InitialVelocity::at_rest (zero; the recording starts at the release), or
//    finite_difference (the second-order one-sided difference of frames 0, 1, 2 at observed
//    nodes, extended to unobserved free nodes by the same static fill, linearised). At rest is
//    the default: a difference of noisy positions injects spurious energy.
//  * dynamics: FemSolver::step per frame interval, Newmark (average acceleration, no numerical
//    damping) with `substeps` per frame. Backward Euler is available only to show its bias: it
//    damps a mode by a ratio of about omega h / 2 on top of Rayleigh damping, so the fitted model
//    over-damps and the Rayleigh coefficients it finds are far too low (PHYSICS.md).
//  * accuracy: the fit can only be as good as the simulation, and what the simulation gets wrong
//    the fit absorbs into the parameters, mostly into the damping: rayleigh_alpha is the weakest
//    term of every mode's decay, so it moves most. Two errors matter. (1) Newmark's period
//    elongation, about (omega h)^2 / 12 per mode: the faster modes drift in phase and the fit
//    damps them away (rayleigh_beta up, rayleigh_alpha down to keep the fundamental's decay).
//    It is second order in h; at half the frame rate (the highest frequency the data resolve) it
//    is (pi / substeps)^2 / 12, 2.3 % with the default 6 substeps. (2) The linearised
//    corotational step (one Newton iteration from the previous positions): the tangent drops the
//    rotation derivative, which leaves an error of first order in h in the end-of-step forces, a
//    slow energy drift that biases the damping. The simulation therefore starts each substep's
//    Newton iteration from the secant prediction (FemStepOptions::extrapolated_newton_start),
//    which makes one iteration as good as converged Newton at no extra cost. On the Table 1 bar
//    (bar_vibration_scenario.hpp, 30 Hz, 250 frames) the fit from the warm start ends at E
//    within 0.01 % and rayleigh_alpha / rayleigh_beta within -0.6 % / +1.7 % with 4 substeps,
//    -0.12 % / +0.34 % with 6, -0.03 % / +0.1 % with 8 (without the prediction, 4 substeps:
//    +1.4 % / +2.4 %). The modal warm start below has no such bias (it compares the data with the
//    model's continuous-time frequencies).
//  * constraints: the recording's fixed nodes stay at rest; driven nodes follow their prescribed
//    positions (the set of driven nodes must be the same in every frame). A measured wrench is
//    applied as an external load (add_spread_wrench over wrench.applied_to, torque moved from the
//    rest centroid to the current one) only when none of those nodes is fixed or driven;
//    otherwise it is the reaction of a prescribed motion and is not used. Gravity as the problem
//    declares it.
//  * residuals: (simulated - observed) / position_noise_m for every coordinate of every free node
//    observed in frames 1..F-1 (frame 0 is the initial condition).
//
// Unknowns: youngs_modulus (one value, or one per control point through MaterialMap: names
// "youngs_modulus[i]"), rayleigh_alpha, rayleigh_beta; each on a log scale with the bounds
// below. A parameter the recording declares (FemRecordingProblem::known_parameters) or that the
// options switch off is held at its known value (problem.material).
//
// Warm start by modal frequency matching (Wang et al.): the lowest `warm_start_modes` modes of the
// model at a reference modulus E0 (clamped at fixed and driven nodes); every frame's observed
// displacement from the rest shape is projected onto them (mass-weighted least squares over the
// observed free nodes); each modal coordinate is fitted with a damped sinusoid (periodogram peak,
// then fit_least_squares on frequency and decay rate with the amplitude and offset solved
// linearly). For a uniform modulus every frequency scales with sqrt(E), so
// E = E0 (f_observed / f_model)^2, averaged in log over the well-fitted modes, weighted by their
// mean square amplitude (control-point maps get this value at every point). The decay rates
// sigma_k = rayleigh_alpha / 2 + rayleigh_beta omega_k^2 / 2 of two or more modes at distinct
// frequencies give both coefficients by non-negative least squares (relative errors); with one
// frequency only, the decay is attributed to rayleigh_beta. Then Levenberg-Marquardt
// (fit_least_squares) on the full trajectory from there.
//
// Jacobian (TrajectoryEstimateOptions::jacobian). By default the simulation carries forward
// sensitivities d x / d log(theta) through every Newmark substep (the step's own factorized
// matrix, one back substitution and one element pass per unknown per substep; the derivation is
// at the top of src/fem_estimation/trajectory_sensitivity.hpp), so one simulation gives the whole
// Jacobian instead of p + 1. They are the derivatives of the converged implicit step with the
// step's own tangent (the rotation derivative dropped): exact for small rotations, and on the
// Table 1 bar within about 1e-3 relative of finite differences of the one-iteration step
// (fem_estimate_dynamic_test). They cover one modulus for the whole body and the Rayleigh
// coefficients with Newmark, at-rest initial velocity and no applied wrench; material maps,
// backward Euler, velocities from the data and applied wrenches use finite differences
// (TrajectoryEstimate::jacobian says which and why).
//
// Stopping at the warm start (stop_when_explained, default on). When the warm start's whitened
// residuals already explain the data, sum r^2 / (residual_count - p) <= 1 + 3 sqrt(2 / dof) (the
// chi-square of pure noise at position_noise_m exceeds this with probability ~0.1 %), the fit
// takes one Levenberg-Marquardt step from there and stops; the standard deviations come from the
// start's Jacobian and the residual scatter after the step. The report (stopped_at_start,
// stop_reason, start_chi_square_per_dof) says so. A start that does not explain the data is
// fitted as before. With position_noise_m too large for the data this stops early; it is the
// noise the caller declares.
//
// Parallelism: fit_least_squares evaluates sequentially. With sensitivities, each trial point is
// one simulation with its sensitivities (the Jacobian the optimiser asks for once it accepts the
// point); a second, plain simulation of it on the other core would answer a little sooner but
// cost CPU time on every accepted step, so there is no parallel work left and `threads` only
// matters with finite differences. There,
// the residual function keeps a cache of recent simulations and, while the optimiser waits for one, runs on the other
// threads the simulations the optimiser's finite differences will ask for next (the points
// value * exp(+difference_step), and with central differences value * exp(-difference_step), of
// each log-scale parameter in turn). A wrong guess only costs an otherwise idle core. Results
// agree across thread counts to rounding (a look-ahead point can differ from the optimiser's own
// in the last bit). Each thread owns a FemModel copy and its solvers.
//
// Units SI: m, s, Pa, 1/s (rayleigh_alpha), s (rayleigh_beta). Host code: allocates, starts
// threads, throws std::invalid_argument for unusable problems or options. Cost: one simulation
// is frame_count * substeps implicit steps (one sparse factorization each). With sensitivities a
// fit takes one simulation with them per iteration (about twice a plain one; two in all when the
// warm start explains the data), with finite differences about (p + 1) / threads plain ones for p
// unknowns ((2 p + 1) / threads with central differences); plus the warm start (a modal analysis
// and small fits, well under a second). Table 1 bar, one modulus: 21 s CPU (before: 61 s).
#pragma once

#include <string>
#include <vector>

#include <Eigen/Core>

#include "pliant/host/fem/fem_recording.hpp"
#include "pliant/host/fem/fem_solver.hpp"
#include "pliant/host/least_squares_fit.hpp"
#include "pliant/host/fem/material_map.hpp"

namespace pliant::host::fem {

enum class InitialVelocity { at_rest, finite_difference };

/// How a recording is simulated (the forward model above).
struct TrajectorySimulationOptions {
  FemIntegrator integrator = FemIntegrator::newmark;
  int substeps = 6;           ///< >= 1 per frame interval (see the accuracy note above)
  int newton_iterations = 1;  ///< >= 1 per substep (1: linearly implicit)
  /// Newton starts each substep from the explicit prediction (FemStepOptions::
  /// extrapolated_newton_start; see the accuracy note above).
  bool extrapolated_newton_start = true;
  InitialVelocity initial_velocity = InitialVelocity::at_rest;
};

/// Simulated positions (3n vectors, m) at every frame of `problem` (frame 0 included) for the
/// given per-element moduli (Pa, one per tetrahedron) and Rayleigh coefficients; the other
/// material values come from problem.material. Throws std::invalid_argument on bad sizes or an
/// unusable problem and std::runtime_error when the solver fails.
std::vector<Eigen::VectorXd> simulate_trajectory(const FemRecordingProblem& problem,
                                                 const Eigen::Ref<const Eigen::VectorXd>& element_youngs_modulus_pa,
                                                 double rayleigh_alpha, double rayleigh_beta,
                                                 const TrajectorySimulationOptions& options = {});

/// How the trajectory fit gets its Jacobian (see "Jacobian" above).
enum class TrajectoryJacobian {
  automatic,           ///< sensitivities where they are available, finite differences otherwise
  sensitivities,       ///< forward sensitivities; std::invalid_argument where not available
  finite_differences,  ///< p + 1 simulations per Jacobian (FitOptions::difference_step)
};

/// simulate_trajectory with the forward sensitivities the fit uses (see "Jacobian" above).
struct TrajectorySensitivities {
  std::vector<Eigen::VectorXd> position_m;  ///< per frame (3n, m), frame 0 included
  /// Per frame, d position / d log(youngs_modulus), d log(rayleigh_alpha), d log(rayleigh_beta)
  /// (three 3n vectors, m).
  std::vector<std::vector<Eigen::VectorXd>> sensitivity_m;
};

/// One modulus for every element. Throws std::invalid_argument where sensitivities are not
/// available (backward Euler, initial velocity from the data, an applied wrench) and like
/// simulate_trajectory otherwise. Cost: about what the fit's Jacobian run costs.
TrajectorySensitivities simulate_trajectory_sensitivities(const FemRecordingProblem& problem, double youngs_modulus_pa,
                                                          double rayleigh_alpha, double rayleigh_beta,
                                                          const TrajectorySimulationOptions& options = {});

struct TrajectoryEstimateOptions {
  /// Which unknowns to fit (a parameter the recording declares is held fixed regardless).
  bool estimate_youngs_modulus = true;
  bool estimate_rayleigh_alpha = true;
  bool estimate_rayleigh_beta = true;
  /// Material control points (m, recording frame). Empty: one modulus for the whole body.
  std::vector<Eigen::Vector3d> control_points_m;
  MaterialMapOptions material_map;

  TrajectorySimulationOptions simulation;

  /// Modal warm start (see above). Off: the fit starts from the initial values below.
  bool warm_start = true;
  int warm_start_modes = 12;  ///< lowest modes projected on (>= 1)

  /// Starting values without a warm start, and the warm start's reference modulus E0.
  /// initial_youngs_modulus_pa = 0: problem.material.youngs_modulus_pa.
  double initial_youngs_modulus_pa = 0;
  /// Starting modulus of each control point (Pa, one per control_points_m entry, each > 0), used
  /// instead of the warm start's uniform value; empty: the warm start or initial_youngs_modulus_pa.
  /// A coarser map's fitted field evaluated at the new points continues a fit from there
  /// (material_map_selection.hpp).
  std::vector<double> initial_control_youngs_modulus_pa;
  double initial_rayleigh_alpha = 0.1;  ///< 1/s
  double initial_rayleigh_beta = 1e-3;  ///< s

  /// Bounds of the fit (log scale, so all > 0).
  double youngs_modulus_min_pa = 1e2, youngs_modulus_max_pa = 1e10;
  double rayleigh_alpha_min = 1e-6, rayleigh_alpha_max = 1e2;
  double rayleigh_beta_min = 1e-8, rayleigh_beta_max = 1.0;

  /// Residual whitening (m, > 0): the position measurement noise. The reported standard
  /// deviations use the residual scatter at the solution (FitResult) either way.
  double position_noise_m = 1e-4;
  /// Optimiser settings. Default here: plain least squares (no robust loss; one pass) with
  /// forward differences (p + 1 simulations per Jacobian instead of 2 p + 1), because each
  /// evaluation is a full simulation.
  FitOptions fit = [] {
    FitOptions f;
    f.loss = RobustLoss::none;
    f.central_differences = false;
    f.max_iterations = 30;
    f.function_tolerance = 1e-6;
    f.parameter_tolerance = 1e-4;  // relative steps below 0.01 % end the fit
    return f;
  }();
  /// Threads running simulations (>= 1); 0: std::thread::hardware_concurrency().
  int threads = 2;
  TrajectoryJacobian jacobian = TrajectoryJacobian::automatic;
  /// Stop after one polishing step when the warm start already explains the data within the
  /// noise (see "Stopping at the warm start" above).
  bool stop_when_explained = true;
  /// Continuation in time: fit the first fraction of the frames (each in (0, 1), ascending),
  /// starting each fit where the previous one ended, before the whole record. A start that is off
  /// in a frequency cannot then lock onto the wrong period over a long record. Empty (default):
  /// automatic, none for one modulus (the warm start matches its frequency) and {0.2, 0.5} with
  /// control points (the warm start is uniform, so the higher modes start off). Values outside
  /// (0, 1) are skipped: {1} means none.
  std::vector<double> window_fractions;
};

/// One mode of the warm start.
struct ModeMeasurement {
  int mode = 0;                      ///< index among the model's lowest modes
  double model_frequency_hz = 0;     ///< at the reference modulus
  double observed_frequency_hz = 0;  ///< undamped natural frequency from the fitted sinusoid
  double decay_rate_1_s = 0;         ///< sigma = zeta omega of the fitted envelope exp(-sigma t)
  double rms_amplitude = 0;          ///< of the modal coordinate (m sqrt(kg), mass-normalised)
  double relative_misfit = 0;        ///< rms residual of the sinusoid fit / rms of the signal
  bool used_for_modulus = false;
  bool used_for_damping = false;
};

struct ModalWarmStart {
  bool modulus_matched = false;  ///< at least one mode gave a frequency
  bool damping_matched = false;  ///< decay rates gave the Rayleigh coefficients
  double reference_youngs_modulus_pa = 0;
  double youngs_modulus_pa = 0;  ///< E0 (f_obs / f_model)^2 (or E0 when not matched)
  double rayleigh_alpha = 0;
  double rayleigh_beta = 0;
  std::vector<ModeMeasurement> modes;
  double wall_time_s = 0;
};

/// The warm start alone (what estimate_trajectory_parameters starts from). Throws like
/// estimate_trajectory_parameters.
ModalWarmStart modal_warm_start(const FemRecordingProblem& problem, const TrajectoryEstimateOptions& options = {});

struct TrajectoryEstimate {
  /// The fitted unknowns, in fit order: youngs_modulus or youngs_modulus[0..k-1], then
  /// rayleigh_alpha, rayleigh_beta (those estimated).
  std::vector<std::string> names;
  std::vector<double> values;
  std::vector<double> standard_deviations;  ///< NaN where the data do not determine a value
  std::vector<double> start_values;         ///< where the fit started (warm start or initial)

  /// Every parameter, estimated or held: per control point (one entry without a map), Pa.
  std::vector<double> control_youngs_modulus_pa;
  std::vector<double> control_youngs_modulus_sd_pa;  ///< 0 when held, NaN when undetermined
  std::vector<Eigen::Vector3d> control_points_m;     ///< empty without a map
  Eigen::VectorXd element_youngs_modulus_pa;         ///< per tetrahedron
  double rayleigh_alpha = 0, rayleigh_alpha_sd = 0;
  double rayleigh_beta = 0, rayleigh_beta_sd = 0;

  ModalWarmStart warm_start;
  double start_residual_rms_m = 0;  ///< rms of (simulated - observed) over residual coordinates
  double residual_rms_m = 0;        ///< the same at the solution
  int residual_count = 0;
  int iterations = 0;         ///< of the fit on the whole record
  int evaluations = 0;        ///< residual-function calls of that fit
  int window_iterations = 0;  ///< of the continuation fits on leading windows
  int window_evaluations = 0;
  int simulations = 0;     ///< forward simulations run (cached repeats not counted;
                           ///< look-ahead ones counted, used or not)
  bool converged = false;  ///< a tolerance was met, or the start explained the data (stopped_at_start)
  std::string message;     ///< the optimiser's summary (after stop_reason when stopped)
  /// "sensitivities", or "finite differences (...)" with the reason (the configuration, or
  /// requested).
  std::string jacobian;
  /// Sum of squared whitened residuals at the start over (residual_count - unknowns), and the
  /// threshold 1 + 3 sqrt(2 / dof) below which the start counts as explaining the data.
  double start_chi_square_per_dof = 0;
  double explained_threshold = 0;
  bool stopped_at_start = false;  ///< one polishing step only (see above)
  std::string stop_reason;        ///< why it stopped or went on (empty without a warm start)
  double wall_time_s = 0;         ///< warm start + fit
  double cpu_time_s = 0;          ///< process CPU time over the same span (all threads)
  FitResult fit;
};

/// Fits the unknowns to the recording (see the file comment). Throws std::invalid_argument when
/// nothing is left to estimate, the recording has fewer than 3 frames or no observed free node
/// after frame 0, the driven node set changes between frames, or options are out of range;
/// std::runtime_error when the simulation fails at the starting values.
TrajectoryEstimate estimate_trajectory_parameters(const FemRecordingProblem& problem,
                                                  const TrajectoryEstimateOptions& options = {});

}  // namespace pliant::host::fem
