// Grasp guard: a per-cycle safety verdict for a two-jaw grasp of a soft object, with the largest
// closure and force the object's MSM model predicts safe at the current msm_beta estimate.
//
// What it decides
//   Every control cycle the caller passes the latest gripper, wrist force/torque, camera
//   (deformation) and estimator samples; the guard returns
//     ok    - continue; command no closure beyond `safe_width_m` and no force above
//             `allowed_force_n` (both also returned).
//     limit - hold: close no further and do not raise the force command; opening is allowed.
//     stop  - execute `stop_action`: `open` (back off to at least the contact width, releasing
//             the squeeze) or `freeze` (stop all jaw motion, keep the current position
//             command). Exceeded limits default to open, faults to freeze.
//   with one dominant `reason`, a bit set of every active reason, and the prediction.
//   Before contact (see GraspGuardConfig::contact_*) closure is 0 and only faults and the force
//   limits can make the verdict not ok.
//
// Units and frames: SI throughout - m, N, N m, s. Widths are the gripper's pad-to-pad opening;
// closure = contact width - width (m, >= 0): the jaw travel past first contact. Strain is the
// largest principal (Biot) strain magnitude of any MSM cluster, |stretch - 1|, dimensionless
// (compression or extension). The wrench is in the F/T sensor frame (only its force part is
// used, for the slip cue). The object model is in metres in the object's frame at first contact,
// and its rest shape is the undeformed object (the tracker's rest shape).
//
// The prediction (init, then a table lookup per cycle)
//   At init the guard squeezes the object's MSM model between two rigid jaw planes normal to
//   `squeeze_axis`, with the core msm_step: each jaw advances closure/2; the particles touching
//   a jaw at first contact, and any that reach a jaw plane at equilibrium, stick to it
//   (position-based contact: projected onto the plane, then driven targets); everything else
//   relaxes to quasi-static equilibrium (msm_alpha 1; the fixed point has zero velocity and
//   does not depend on msm_alpha or the time step; the iteration carries momentum, which only
//   speeds it up). No gravity, and the elastic model only (no plasticity or relaxation).
//   It does this for `prediction_beta_points` msm_beta values on [0, 1] and
//   `prediction_closure_points` closures on (0, max closure] (default: twice the stop threshold
//   under uniform compression), tabulating the largest cluster strain (rows end at twice the
//   stop threshold and are extrapolated), and locates where each beta's strain first exceeds `max_strain` to 1 /
//   `prediction_refine_steps` of a closure step (the last refined closure at or below the
//   limit is kept: conservative at that resolution).
//   Per cycle the estimate gives the interval beta +- confidence_k sd (clipped to [0, 1]; the
//   whole of [0, 1] while the estimate is stale, invalid or its sd infinite), and the safe
//   closure is the smallest tabulated crossing over the grid betas bracketing that interval.
//   In MSM, lower beta (stiffer clusters) concentrates the squeeze at the jaws and gives the
//   higher strain at the same closure, so the guard takes the worst case over the interval,
//   not the "softer" end. Where the strain never reaches the limit inside the table, the safe
//   closure is the table's end (no prediction beyond it).
//   Force: MSM has no force scale, so the force prediction comes from the measurements.
//   (closure, force) samples are admitted every force_fit_spacing_m of closure; the stiffness is
//   the largest of the secant (force / closure), the slope of an exponentially weighted line fit
//   over the admitted samples, and the slope over the latest admitted segment (the current
//   tangent), and the force is extrapolated linearly from the current one. It is still
//   optimistic for an object that stiffens sharply ahead of the data; the force limits are also
//   enforced on the measured force every cycle.
//   safe_closure_m = min(strain prediction, max_indentation_m, closure where the extrapolated
//   force reaches allowed_force_n).
//
// Faults (not ok within the cycle they are seen)
//   Per source (gripper, wrench, camera, estimate, and the guard's own clock): a non-finite
//   value or timestamp (nan_input); valid == false, a value out of range, a timestamp in the
//   future (beyond clock_tolerance_s) or going backwards (invalid_input); a status bit in the
//   source's fault mask (sensor_fault); bus_off; a driver-reported timeout, or the guard itself
//   not called within cycle_timeout_s (timeout); now - stamp > the source's timeout (stale_*;
//   also a wrench repeated bit for bit wrench_frozen_samples times). The verdict of a fault is
//   config.fault_verdict[source] (limit or stop; defaults: gripper, wrench and clock stop,
//   camera and estimate limit).
//
// Hysteresis: a reason is set in the cycle its condition holds and cleared only after
//   `clear_samples` consecutive new samples of its source with the measure below
//   threshold x (1 - hysteresis_margin) (faults: without the fault). While a source delivers
//   nothing new its reasons keep their state. Limits: `..._limit` at the limit (limit),
//   `..._exceeded` at limit x (1 + stop_overshoot) (stop).
//
// Slip (after the PR2 gripper sensor controller): the wrist force is high-pass filtered
//   (first order, slip_cutoff_hz); slip is flagged while its magnitude exceeds
//   clamp(slip_ratio x grip force, slip_floor_n, slip_ceiling_n). While slipping in contact
//   with a usable wrench, allowed_force_n grows by slip_force_rate_per_s x dt per cycle, never
//   above max_force_n. It never decreases within a grasp; grasp_guard_reset restores
//   nominal_force_n.
//
// Lifecycle and memory (no heap, ever):
//   model: the object's MsmModel (msm_model.hpp) with EVERY particle drivable and none fixed
//          (either jaw may touch any particle), built by the caller; it must outlive the guard
//          only for grasp_guard_measure_strain.
//   std::size_t bytes = grasp_guard_workspace_size(model, config);   // init time
//   Arena arena(block, bytes);                                        // caller-owned
//   Status s = grasp_guard_init(arena, model, object, config, guard); // init time: runs
//       beta_points x (closure_points + refine_steps) quasi-static relaxations of at most
//       relax_max_iterations msm_steps each (a 100-particle 3D object: ~0.1 s)
//   per cycle: grasp_guard_update (real-time, O(beta_points), no allocation, no exceptions;
//       about 1 us);
//   per camera frame: grasp_guard_measure_strain (real-time, O(cluster memberships); about
//       12 us for 123 particles in 3D: run it in the tracker's frame loop).
//   The caller owns the block; it must outlive the guard (the table lives there). It also
//   holds the init-time simulation state (unused afterwards).
// Thread safety: one guard per control loop; no internal locking. grasp_guard_measure_strain
// reads only what init wrote, so it may run on the tracker's thread while the control thread
// calls grasp_guard_update.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include "pliant/core/msm.hpp"

namespace pliant {

enum class GraspVerdict : std::uint8_t { ok = 0, limit = 1, stop = 2 };

// --- the status-word conventions behind the default fault masks ------------------------------------
// The core cannot include hal/, so the bits are repeated here; hal/guard_inputs.hpp checks at
// compile time that they equal the HAL's constants (docs/grasp_guard.md, "Status words").
/// The stream monitor's "do not trust this sample" flags, bits 17-21 (hal/stream_monitor.hpp):
/// stamp stall, backwards, jump, frozen payload, non-finite. Bit 16 (a sequence gap) only
/// counts a drop and is not among them.
inline constexpr std::uint32_t kGuardStreamFaultBits = 0x003e0000u;
/// Gripper: the fault code byte, bits 8-15 (hal/gripper.hpp; a Robotiq's gFLT | kFLT << 4). Bits
/// 0-3 (activated, moving, object detected, at target) are states, never faults.
inline constexpr std::uint32_t kGuardGripperFaultBits = 0x0000ff00u;
/// Wrench: the ATI NETCANOEM status bits that make a reading untrustworthy, 1-7, 11, 12
/// (hal/force_torque.hpp); bit 0 (watchdog reset) and bit 14 (CAN transport degraded) are not.
inline constexpr std::uint32_t kGuardWrenchFaultBits = 0x000018feu;
/// Camera: the device marked the frame unusable (bit 0, hal/camera.hpp). A partial frame (bit 1:
/// particles occluded, e.g. by the jaws) is normal during a grasp and is not a fault.
inline constexpr std::uint32_t kGuardCameraFaultBits = 0x00000001u;

enum class StopAction : std::uint8_t {
  freeze,  ///< stop all jaw motion; keep the current position command
  open,    ///< open to at least the contact width (release the squeeze)
};

/// Why the verdict is not ok. The numeric order is the priority among reasons of the same
/// verdict: exceeded limits first, then faults, then limits. Bit (1u << reason) in `reasons`.
enum class GuardReason : std::uint8_t {
  none = 0,
  force_exceeded,        ///< stop: grip force >= max_force_n x (1 + stop_overshoot)
  strain_exceeded,       ///< stop: measured strain >= max_strain x (1 + stop_overshoot)
  indentation_exceeded,  ///< stop: closure >= max_indentation_m x (1 + stop_overshoot)
  not_configured,        ///< stop: guard not initialised, or contact width contradicts the model
  nan_input,             ///< a non-finite value or timestamp
  invalid_input,         ///< valid flag false, out of range, timestamp in the future or backwards
  sensor_fault,          ///< a status bit in the source's fault mask
  bus_off,               ///< the source's bus is off
  timeout,               ///< driver-reported timeout, or the guard not called within cycle_timeout_s
  stale_gripper,         ///< gripper sample older than gripper_timeout_s
  stale_wrench,          ///< wrench sample older than wrench_timeout_s, or frozen
  stale_camera,          ///< deformation sample older than camera_timeout_s
  stale_estimate,        ///< estimate older than estimate_timeout_s
  force_limit,           ///< limit: grip force >= allowed_force_n
  strain_limit,          ///< limit: measured strain >= max_strain
  indentation_limit,     ///< limit: closure >= max_indentation_m
  predicted_strain,      ///< limit: closure >= the MSM-predicted safe closure
  estimate_uncertain,    ///< msm_beta_std >= max_beta_std (verdict: uncertain_estimate_verdict)
  count
};
inline constexpr int kGuardReasonCount = static_cast<int>(GuardReason::count);

enum class GuardSource : std::uint8_t { gripper = 0, wrench, camera, estimate, clock, count };
inline constexpr int kGuardSourceCount = static_cast<int>(GuardSource::count);

enum class ForceSource : std::uint8_t {
  force_sensor,   ///< GripperSample::force_n
  motor_current,  ///< current_gain_n_per_a x (GripperSample::current_a - current_offset_a)
};

/// Short, stable names ("force_limit", "stale_camera", ...), for logs.
const char* guard_reason_name(GuardReason reason) noexcept;
const char* grasp_verdict_name(GraspVerdict verdict) noexcept;
const char* guard_source_name(GuardSource source) noexcept;

struct GraspGuardConfig {
  static constexpr double kInf = std::numeric_limits<double>::infinity();
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

  // --- the object's limits ---------------------------------------------------------------------
  double max_strain = 0.1;          ///< largest cluster principal strain; > 0, +inf: none
  double max_indentation_m = kInf;  ///< closure past contact (PR2's deformation_limit); > 0
  double max_force_n = 10;          ///< hard grip-force limit, finite > 0; slip never exceeds it
  double nominal_force_n = kNaN;    ///< allowed force without slip, (0, max]; NaN: max_force_n

  // --- contact -----------------------------------------------------------------------------------
  /// Width at first contact, m. NaN: detected as the width of the first usable gripper sample
  /// with force >= contact_force_n (PR2's position marker).
  double contact_width_m = kNaN;
  double contact_force_n = 0.5;
  /// A detected contact width whose difference from the model's extent along the squeeze axis
  /// exceeds this fraction of that extent raises not_configured (wrong object or unit).
  double contact_width_tolerance = 0.5;
  double max_width_m = 0.5;  ///< gripper widths outside [0, max_width_m] are invalid_input

  // --- grip force from the gripper ----------------------------------------------------------------
  ForceSource force_source = ForceSource::force_sensor;
  double current_gain_n_per_a = 0;  ///< motor_current: N per A, finite > 0
  double current_offset_a = 0;

  // --- freshness, s (monotonic clock, the same as GraspGuardInput::now_s) -------------------------
  double gripper_timeout_s = 0.02;
  double wrench_timeout_s = 0.02;
  double camera_timeout_s = 0.1;
  double estimate_timeout_s = 0.5;
  double cycle_timeout_s = 0.02;     ///< longest gap between two guard cycles
  double clock_tolerance_s = 0.002;  ///< how far a sample stamp may lie in the future
  int wrench_frozen_samples = 0;     ///< bit-identical wrench samples that mean frozen; 0: off

  // --- status words: set bits in the mask are faults -----------------------------------------------
  // The defaults follow the HAL's status words plus the stream monitor's flags (the constants
  // above), right for every gripper, force/torque sensor and camera pliant's drivers read. A
  // driver of your own maps its device's word onto the same bits, or sets its own masks here.
  std::uint32_t gripper_fault_mask = kGuardGripperFaultBits | kGuardStreamFaultBits;
  /// ATI NETCANOEM status bits 1-7, 11, 12 (docs/drivers/socketcan.md); map other sensors'
  /// words to them.
  std::uint32_t wrench_fault_mask = kGuardWrenchFaultBits | kGuardStreamFaultBits;
  std::uint32_t camera_fault_mask = kGuardCameraFaultBits | kGuardStreamFaultBits;

  // --- verdicts and hysteresis --------------------------------------------------------------------------
  /// Verdict of a fault per GuardSource (limit or stop; ok is refused at init).
  GraspVerdict fault_verdict[kGuardSourceCount] = {GraspVerdict::stop, GraspVerdict::stop, GraspVerdict::limit,
                                                   GraspVerdict::limit, GraspVerdict::stop};
  /// Verdict of estimate_uncertain. ok (default): reported only; the prediction then already
  /// uses the whole beta interval the sd allows.
  GraspVerdict uncertain_estimate_verdict = GraspVerdict::ok;
  StopAction exceeded_stop_action = StopAction::open;  ///< stop for a *_exceeded reason
  StopAction fault_stop_action = StopAction::freeze;   ///< stop for a fault
  /// true: a stop verdict persists until grasp_guard_acknowledge_stop or grasp_guard_reset.
  bool latch_stop = false;
  double hysteresis_margin = 0.05;  ///< [0, 1)
  int clear_samples = 5;            ///< >= 1 consecutive clear samples of the reason's source
  double stop_overshoot = 0.1;      ///< >= 0

  // --- the estimate ------------------------------------------------------------------------------
  double confidence_k = 2;     ///< interval half-width in sd, >= 0
  double max_beta_std = 0.15;  ///< sd at and above which estimate_uncertain is raised; > 0

  // --- slip cue (PR2: 5 Hz high-pass, band 0.007 |F| clamped to [0.048, 0.2] N, +0.2 %/cycle) --
  double slip_cutoff_hz = 5;
  double slip_ratio = 0.007;
  double slip_floor_n = 0.048;
  double slip_ceiling_n = 0.2;
  double slip_force_rate_per_s = 2;  ///< relative force increase per second while slipping

  // --- force model -----------------------------------------------------------------------------------
  double force_fit_spacing_m = 1e-4;        ///< closure between admitted (closure, force) samples
  double force_fit_forgetting = 0.7;        ///< weight kept per admitted sample, (0, 1]
  double force_model_min_closure_m = 2e-4;  ///< no force prediction below this closure

  // --- prediction table (init) ---------------------------------------------------------------------
  int prediction_beta_points = 11;     ///< >= 2, msm_beta = j / (points - 1)
  int prediction_closure_points = 32;  ///< >= 2 closure steps up to the max closure
  int prediction_refine_steps = 8;     ///< >= 1 sub-steps locating each crossing
  /// NaN: 2 x max_strain x (1 + stop_overshoot) x the object's extent along the axis (twice
  /// the stop threshold under uniform compression), at most half the extent.
  double prediction_max_closure_m = kNaN;
  int relax_max_iterations = 3000;  ///< >= 1 msm_steps per quasi-static relaxation
  double relax_tolerance = 1e-6;    ///< converged when no particle moves more (x spacing)
};

/// The object and how the jaws meet it (init only; arrays are read during init).
template <int Dim, typename Scalar>
struct GraspObject {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  /// Squeeze direction in the model frame, from jaw A toward jaw B; normalised at init.
  Vec squeeze_axis = Vec::Zero();
  /// Particles touching each jaw at first contact. Empty: those within contact_band x model
  /// spacing of the extreme rest positions along the axis. More particles join as they reach
  /// a jaw plane during the squeeze.
  const int* jaw_a_ids = nullptr;
  int jaw_a_count = 0;
  const int* jaw_b_ids = nullptr;
  int jaw_b_count = 0;
  double contact_band = 0.25;
};

// --- per-cycle inputs: each sample carries its own stamp (the monotonic clock of now_s) --------

struct GripperSample {
  double stamp_s = GraspGuardConfig::kNaN;
  double width_m = GraspGuardConfig::kNaN;    ///< pad-to-pad opening
  double force_n = GraspGuardConfig::kNaN;    ///< grip force (force_sensor)
  double current_a = GraspGuardConfig::kNaN;  ///< motor current (motor_current)
  std::uint32_t status_bits = 0;              ///< driver status word, see gripper_fault_mask
  bool valid = false;
  bool bus_off = false;
  bool timeout = false;
};

struct WrenchSample {
  double stamp_s = GraspGuardConfig::kNaN;
  double wrench[6] = {GraspGuardConfig::kNaN, GraspGuardConfig::kNaN, GraspGuardConfig::kNaN, GraspGuardConfig::kNaN,
                      GraspGuardConfig::kNaN, GraspGuardConfig::kNaN};  ///< Fx Fy Fz N, Tx Ty Tz N m
  std::uint32_t status_bits = 0;                                        ///< e.g. the ATI status word
  bool valid = false;
  bool bus_off = false;
  bool timeout = false;
};

/// The tracked deformation of the latest camera frame, stamped with its capture time.
struct DeformationSample {
  double stamp_s = GraspGuardConfig::kNaN;
  double strain = GraspGuardConfig::kNaN;  ///< grasp_guard_measure_strain's value (or the caller's)
  std::uint32_t status_bits = 0;
  bool valid = false;
  bool bus_off = false;
  bool timeout = false;
};

/// The current deformability estimate (e.g. online_deformability_estimate).
struct EstimateSample {
  double stamp_s = GraspGuardConfig::kNaN;
  double msm_beta = GraspGuardConfig::kNaN;      ///< [0, 1]
  double msm_beta_std = GraspGuardConfig::kNaN;  ///< >= 0; +inf: not yet identifiable
  bool valid = false;
};

struct GraspGuardInput {
  double now_s = GraspGuardConfig::kNaN;  ///< this cycle's time, monotonic seconds
  GripperSample gripper;
  WrenchSample wrench;
  DeformationSample deformation;
  EstimateSample estimate;
};

struct GraspGuardOutput {
  GraspVerdict verdict = GraspVerdict::stop;
  GuardReason reason = GuardReason::not_configured;  ///< dominant reason; none when ok
  StopAction stop_action = StopAction::freeze;       ///< what stop means this cycle
  std::uint32_t reasons = 0;                         ///< bit (1u << reason) per active reason, informational ones too
  std::uint8_t fault_sources = 0;                    ///< bit (1u << source) per source with an active fault
  bool in_contact = false;
  bool slip = false;  ///< slip cue active this cycle
  double contact_width_m = GraspGuardConfig::kNaN;
  double closure_m = 0;                                  ///< contact width - width, >= 0 (0 before contact)
  double force_n = GraspGuardConfig::kNaN;               ///< grip force used this cycle
  double strain = GraspGuardConfig::kNaN;                ///< measured strain used this cycle
  double allowed_force_n = GraspGuardConfig::kNaN;       ///< nominal, raised by slip, <= max_force_n
  double beta_low = 0, beta_high = 1;                    ///< msm_beta interval of the prediction
  double predicted_strain = GraspGuardConfig::kNaN;      ///< at the current closure, worst over the interval
  double strain_safe_closure_m = 0;                      ///< largest closure keeping the predicted strain <= max_strain
  double force_safe_closure_m = GraspGuardConfig::kInf;  ///< where the predicted force reaches allowed_force_n
  double safe_closure_m = 0;                             ///< min of the above and max_indentation_m
  double safe_width_m = GraspGuardConfig::kNaN;          ///< contact width - safe_closure_m (NaN before contact)
  /// Grip force the force model predicts at safe_closure_m: the largest force predicted safe
  /// (allowed_force_n itself when the force bounds the closure). NaN without a force model.
  double predicted_force_n = GraspGuardConfig::kNaN;
  double stiffness_n_per_m = GraspGuardConfig::kNaN;  ///< slope used by the force model
  double slip_force_n = 0;                            ///< magnitude of the high-passed wrist force
};

/// Monotonic counters: every refused or stale input is counted.
struct GraspGuardCounters {
  std::uint32_t cycles = 0;
  std::uint32_t limit_cycles = 0;
  std::uint32_t stop_cycles = 0;
  std::uint32_t slip_cycles = 0;
  std::uint32_t refused[kGuardSourceCount] = {};       ///< cycles a source's input was refused (nan, invalid, fault)
  std::uint32_t stale_cycles[kGuardSourceCount] = {};  ///< cycles a source was stale
};

/// One reason's latch: set at once, cleared after clear_samples clear samples.
struct GuardLatch {
  bool active = false;
  std::int32_t clear_count = 0;
};

/// Per-grasp state, updated every cycle (read-only for callers).
struct GraspGuardState {
  static constexpr int kFaultKinds = 6;  // nan, invalid, sensor, bus_off, timeout, stale
  GuardLatch fault[kFaultKinds][kGuardSourceCount];
  GuardLatch measured[kGuardReasonCount];  ///< indexed by GuardReason (limits, exceeded, uncertain)
  bool geometry_mismatch = false;
  bool stop_latched = false;
  GuardReason latched_reason = GuardReason::none;
  StopAction latched_action = StopAction::freeze;
  bool has_now = false;
  double last_now_s = 0;
  double last_stamp_s[kGuardSourceCount] = {};  ///< stamp of the last sample seen per source
  bool seen[kGuardSourceCount] = {};
  // accepted values
  double width_m = GraspGuardConfig::kNaN;
  double force_n = GraspGuardConfig::kNaN;
  double strain = GraspGuardConfig::kNaN;
  double msm_beta = GraspGuardConfig::kNaN;
  double msm_beta_std = GraspGuardConfig::kInf;
  bool has_gripper = false, has_strain = false, has_estimate = false;
  // contact
  bool in_contact = false;
  double contact_width_m = GraspGuardConfig::kNaN;
  // slip
  bool has_wrench = false;
  double previous_force[3] = {0, 0, 0};
  double high_pass[3] = {0, 0, 0};
  double wrench_stamp_s = 0;  ///< stamp of the last wrench sample the filter used
  double previous_wrench[6] = {0, 0, 0, 0, 0, 0};
  bool frozen_seen = false;
  std::int32_t frozen_count = 0;
  double slip_force_n = 0;
  bool slip = false;
  double allowed_force_n = 0;
  // force fit: exponentially weighted sums over admitted (closure, force) samples
  double fit_w = 0, fit_x = 0, fit_y = 0, fit_xx = 0, fit_xy = 0;
  std::int32_t fit_samples = 0;
  double fit_last_closure_m = -GraspGuardConfig::kInf;
  double fit_last_force_n = 0;
  double fit_segment_slope = GraspGuardConfig::kNaN;  ///< force slope over the latest admitted segment
};

template <int Dim, typename Scalar>
struct GraspGuard {
  using Vec = Eigen::Matrix<Scalar, Dim, 1>;
  using MatD = Eigen::Matrix<double, Dim, Dim>;
  GraspGuardConfig config;  ///< validated copy (nominal_force_n resolved)
  int particle_count = 0;
  int cluster_count = 0;
  Vec squeeze_axis = Vec::Zero();  ///< unit
  double extent_m = 0;             ///< the model's extent along the axis (extreme particle centres)
  int beta_points = 0;
  int closure_points = 0;
  double closure_step_m = 0;  ///< table closure k x closure_step_m, k = 0..closure_points
  /// [beta_points x (closure_points + 1)], row j = msm_beta j / (beta_points - 1): predicted
  /// largest cluster strain at each tabulated closure.
  double* strain_table = nullptr;
  /// [beta_points]: largest closure with predicted strain <= max_strain (refined), or the
  /// table's end when the limit is never reached inside it.
  double* crossing_closure_m = nullptr;
  /// Per beta: the closure step holding the crossing (-1: none) and the strain at its
  /// prediction_refine_steps + 1 refined sub-steps ([beta_points x (refine_steps + 1)]), so the
  /// predicted strain agrees with the refined crossing.
  int* refined_segment = nullptr;
  double* refined_strain = nullptr;
  /// [cluster_count] projector onto directions a flat or collinear cluster does not span
  /// (zero for full-rank clusters); keeps them out of the strain.
  MatD* cluster_null = nullptr;
  int unconverged_relaxations = 0;  ///< init relaxations that hit relax_max_iterations
  long relaxation_steps = 0;        ///< msm_steps spent at init
  GraspGuardState state;
  GraspGuardCounters counters;
  bool initialized() const noexcept { return strain_table != nullptr; }
};

/// Bytes of caller memory grasp_guard_init needs (0 when the model is not initialised).
template <int Dim, typename Scalar>
std::size_t grasp_guard_workspace_size(const MsmModel<Dim, Scalar>& model, const GraspGuardConfig& config) noexcept;

/// Validates, builds the prediction table and resets the guard. Init time only (see the top of
/// the file for the cost). Errors: not_initialized (model), invalid_argument (a config field
/// out of its documented range, a model particle not drivable or fixed, jaw ids out of range,
/// empty or shared between the jaws, a zero axis or extent), capacity_exceeded. On error the
/// guard is left uninitialised (its update then answers stop / not_configured).
template <int Dim, typename Scalar>
[[nodiscard]] Status grasp_guard_init(Arena& arena, const MsmModel<Dim, Scalar>& model,
                                      const GraspObject<Dim, Scalar>& object, const GraspGuardConfig& config,
                                      GraspGuard<Dim, Scalar>& guard) noexcept;

/// A new grasp: forgets contact, force fit, slip state and measured-limit reasons, restores
/// nominal_force_n and clears a latched stop. Fault reasons keep their hysteresis. Real-time safe.
template <int Dim, typename Scalar>
void grasp_guard_reset(GraspGuard<Dim, Scalar>& guard) noexcept;

/// Clears a stop held by latch_stop (it re-latches next cycle if its cause persists).
template <int Dim, typename Scalar>
void grasp_guard_acknowledge_stop(GraspGuard<Dim, Scalar>& guard) noexcept;

/// One control cycle. Real-time safe: O(prediction_beta_points), no allocation, no exceptions.
/// Returns ok (the verdict, whatever it is, is in `output`) or not_initialized (output: stop,
/// not_configured, freeze).
template <int Dim, typename Scalar>
[[nodiscard]] Status grasp_guard_update(GraspGuard<Dim, Scalar>& guard, const GraspGuardInput& input,
                                        GraspGuardOutput& output) noexcept;

/// The strain of one tracked frame, for DeformationSample::strain.
struct GraspStrainMeasurement {
  double strain = GraspGuardConfig::kNaN;  ///< largest cluster principal strain; NaN if none measured
  int cluster = -1;                        ///< the cluster holding it
  int clusters_measured = 0;
  int clusters_skipped = 0;  ///< clusters with an unobserved (non-finite) member
};

/// Strain of `positions` ([particle_count], the model's particles in any Euclidean frame, m)
/// against the model's rest shape: per cluster the affine fit A = A_pq A_qq^+ (eq. 7 of the MSM
/// paper), principal stretches = sqrt(eigenvalues of A^T A) within the cluster's span, strain =
/// largest |stretch - 1|. Rigid motion gives 0. Clusters with a non-finite member are skipped.
/// Returns ok, no_observations (nothing measured; strain NaN), invalid_argument (positions null
/// or the model is not the guard's) or not_initialized. Real-time safe, O(memberships).
template <int Dim, typename Scalar>
[[nodiscard]] Status grasp_guard_measure_strain(const MsmModel<Dim, Scalar>& model,
                                                const GraspGuard<Dim, Scalar>& guard,
                                                const Eigen::Matrix<Scalar, Dim, 1>* positions,
                                                GraspStrainMeasurement& measurement) noexcept;

/// Predicted largest strain at `closure_m` for msm_beta in [beta_low, beta_high] (the table,
/// worst over the bracketing grid betas, linear in closure; linear extrapolation past the
/// table). For tests and tools; real-time safe.
template <int Dim, typename Scalar>
double grasp_guard_predicted_strain(const GraspGuard<Dim, Scalar>& guard, double closure_m, double beta_low,
                                    double beta_high) noexcept;

/// Largest closure predicted safe for msm_beta in [beta_low, beta_high]. Real-time safe.
template <int Dim, typename Scalar>
double grasp_guard_strain_safe_closure(const GraspGuard<Dim, Scalar>& guard, double beta_low,
                                       double beta_high) noexcept;

}  // namespace pliant
