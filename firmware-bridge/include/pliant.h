/* pliant.h: the C99 interface that controller firmware links (library pliant_bridge).
 *
 * WHAT IT DOES
 *   pliant learns how soft an object is from what the robot sees while it squeezes it, and keeps
 *   the grasp safe. Through this header a firmware:
 *     1. describes the object once (particles of its rest shape, clusters, limits, jaws),
 *     2. asks how many bytes that needs and hands over one memory block,
 *     3. per camera frame: pushes the observed particle positions and the tool contact, steps
 *        the MSM-regularised tracker, updates the online deformability estimate (msm_beta),
 *     4. per control cycle: feeds gripper, wrist wrench and the above to the grasp guard and
 *        obeys its verdict: OK (continue), LIMIT (close no further), STOP (open or freeze).
 *
 * CONVENTIONS (libcanard style)
 *   - Every function is pliant_*, every type pliant_*_t, every macro PLIANT_*. The instance is
 *     the first argument. Every function returns a pliant_status_t (0 = PLIANT_OK) unless it is
 *     a pure query (names, version).
 *   - Nothing allocates, nothing throws, nothing blocks, nothing reads a clock: time is passed
 *     in. All memory is the caller's block; the library keeps no global state except the
 *     assert handler (pliant_set_assert_handler).
 *   - Every call validates its pointers, sizes, values and the call order. A refused call
 *     changes nothing, returns an error status and, when the instance is usable, is counted in
 *     pliant_counters_t.calls_rejected (with the status and the call in last_rejected_*). A
 *     call with a NULL or uninitialised instance cannot be counted (there is nothing to count
 *     in); it only returns the status.
 *   - Units are SI: metres, seconds, newtons. Times are seconds on ONE monotonic clock of the
 *     firmware's choosing (the same clock for every stamp and for the guard's now_s).
 *   - Types on the interface are fixed: positions are float (the object frame, metres), times,
 *     limits and guard values are double. The library computes internally in double (the
 *     default) or float, chosen when it is built (CMake option PLIANT_BRIDGE_DOUBLE); this
 *     header is the same either way. Enumerated fields inside structs are uint8_t, so struct
 *     layouts do not depend on the compiler's enum size.
 *   - Arrays of per-particle values are particle-major: element (i, axis) at [i * dim + axis].
 *
 * FOOTPRINT AND TIMING (N particles, C clusters, K estimator candidates per form, A x S forms)
 *   The block holds the object model twice (the tracker's and the guard's), the tracker, A x S x K
 *   MSM states for the estimator (the largest part), the guard's prediction table and its init-time
 *   simulation, and per-frame buffers: O(A S K (N + C) + memberships) bytes. Measured with the
 *   defaults (x86-64, A = 3, S = 1): a 4x4x3 block (N = 48) needs 893 KB computing in double;
 *   an 8x4 2D sheet 351 KB (with A = 1: 407 KB and 164 KB in double, 214 KB and 92 KB in
 *   float). Without the estimator a fifth of that. The quasi-static row (equilibrium_iterations
 *   > 0) adds one form: K more states, and up to K x equilibrium_iterations MSM steps per frame.
 *   Ask pliant_workspace_size for your object.
 *   pliant_init is SLOW: it builds the models (O(N^2)) and the guard's prediction table
 *   (prediction_beta_points x (prediction_closure_points + prediction_refine_steps) quasi-static
 *   MSM relaxations of up to relax_max_iterations steps each): 25 ms for N = 48 on a desktop
 *   core, expect tens of times longer on a Cortex-M7. Call it before the control loop.
 *   Real-time calls, N = 48, desktop core, double: pliant_push_observations +
 *   pliant_step_tracker about 30 us; pliant_update_estimate about 60 us per row of K = 11
 *   candidates, A (2^S - 1) rows' worth (bench/online_bench, the core update alone, 32
 *   particles in double: 16 us for one row and 50 us for the default three in 2D, 63 and
 *   227 us in 3D);
 *   pliant_guard_update about 0.3 us, O(prediction_beta_points). None allocates, blocks or
 *   loops without bound.
 *
 * THREADING
 *   No internal locking. Either make every call on an instance from one context, or split it
 *   in two groups that may run concurrently (for example a frame task and a control interrupt
 *   that preempts it):
 *     frame group: pliant_push_observations, pliant_push_tool_contact, pliant_step_tracker,
 *                  pliant_update_estimate, pliant_get_tracked, pliant_get_estimate,
 *                  pliant_get_deformation;
 *     cycle group: pliant_guard_update, pliant_reset_grasp_guard, pliant_acknowledge_stop;
 *   provided the cycle group passes the deformation and estimate samples itself
 *   (PLIANT_SOURCE_CALLER): the frame group reads them with pliant_get_deformation and
 *   pliant_get_estimate and hands them over through the firmware's own mailbox. In that mode
 *   pliant_get_counters, pliant_get_info, pliant_reset_grasp, pliant_telemetry_bytes and
 *   pliant_emit_telemetry touch both groups: call them where neither group runs (e.g. in the
 *   frame task with the control interrupt masked). Different instances are independent.
 *
 * THE LOOP (error handling shortened; every status should be checked)
 *
 *   static uint8_t g_block[512 * 1024];  // 48 particles in 3D with the defaults need 407 KB
 *   pliant_t* g_pliant;
 *
 *   void setup(const float* rest_xyz, uint32_t n) {
 *       pliant_config_t cfg;
 *       pliant_config_init_default(&cfg);          // required: also stamps the ABI check
 *       cfg.dim = 3;
 *       cfg.particle_count = n;
 *       cfg.rest_positions = rest_xyz;            // first (still) camera frame, metres
 *       cfg.guard.max_strain = 0.08;              // the object's limits
 *       cfg.guard.max_force_n = 15.0;
 *       cfg.guard.squeeze_axis[0] = 1.0;          // jaw A -> jaw B in the object frame
 *       size_t need = 0;
 *       if (pliant_workspace_size(&cfg, &need) != PLIANT_OK || need > sizeof g_block) fail();
 *       if (pliant_init(g_block, sizeof g_block, &cfg, &g_pliant) != PLIANT_OK) fail();
 *   }
 *
 *   void on_camera_frame(double stamp_s, uint64_t stamp_us, double dt_s, const float* xyz,
 *                        const float* conf) {
 *       pliant_push_observations(g_pliant, stamp_s, xyz, conf);     // copies
 *       pliant_push_tool_contact(g_pliant, ids, targets_xyz, count); // optional
 *       pliant_step_tracker(g_pliant, dt_s);
 *       pliant_update_estimate(g_pliant);
 *       static uint8_t tx[4096];                                     // optional: stream results
 *       size_t n = 0;
 *       if (pliant_emit_telemetry(g_pliant, PLIANT_TELEMETRY_ALL, stamp_us, tx, sizeof tx, &n) == PLIANT_OK)
 *           uart_send(tx, n);
 *   }
 *
 *   void control_cycle(double now_s) {                               // e.g. 1 kHz
 *       pliant_guard_input_t in;
 *       pliant_verdict_t v;
 *       pliant_guard_input_init(&in);              // deformation and estimate: the bridge's own
 *       in.now_s = now_s;
 *       in.gripper.stamp_s = gripper.stamp_s; in.gripper.width_m = gripper.width_m;
 *       in.gripper.force_n = gripper.force_n; in.gripper.valid = gripper.ok;
 *       in.wrench.stamp_s = ft.stamp_s; memcpy(in.wrench.wrench, ft.wrench, sizeof ft.wrench);
 *       in.wrench.status_bits = ft.status; in.wrench.valid = ft.ok;
 *       in.deformation.timeout = camera_timed_out;
 *       if (pliant_guard_update(g_pliant, &in, &v) != PLIANT_OK) v.verdict = PLIANT_VERDICT_STOP;
 *       if (v.verdict == PLIANT_VERDICT_OK)         command(max(wanted_width, v.safe_width_m));
 *       else if (v.verdict == PLIANT_VERDICT_LIMIT) hold();     // close no further
 *       else if (v.stop_action == PLIANT_STOP_OPEN) open_to(v.contact_width_m);
 *       else                                        freeze();
 *   }
 *
 *   A new grasp of the same object (released, back at rest): pliant_reset_grasp. Another
 *   object: pliant_init again (the block may be reused).
 */
#ifndef PLIANT_H
#define PLIANT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ============================================================================================
 * Version and ABI
 * ========================================================================================== */

#define PLIANT_VERSION_MAJOR 0
#define PLIANT_VERSION_MINOR 1
#define PLIANT_VERSION_PATCH 0
/** (major << 16) | (minor << 8) | patch, as pliant_version() returns it (unsigned). */
#define PLIANT_VERSION_NUMBER ((PLIANT_VERSION_MAJOR * 65536U) + (PLIANT_VERSION_MINOR * 256U) + PLIANT_VERSION_PATCH)

/** Bumped whenever any struct or enumeration value of this header changes. A firmware
 *  compiled against a header with another ABI version is refused (PLIANT_ERROR_ABI_MISMATCH). */
#define PLIANT_ABI_VERSION 3U

/** The library's version, packed as PLIANT_VERSION_NUMBER. Compare it with the header's
 *  PLIANT_VERSION_NUMBER to detect a stale library. Constant time, real-time safe. */
uint32_t pliant_version(void);
/** "major.minor.patch", static storage. */
const char* pliant_version_string(void);
/** The library's PLIANT_ABI_VERSION. */
uint32_t pliant_abi_version(void);

/** The layout a caller was compiled with: sizes of every struct that crosses this interface.
 *  Filled in by pliant_config_init_default (an inline function, so it measures the caller's
 *  header) and checked by pliant_workspace_size and pliant_init. */
typedef struct pliant_abi_s {
  uint32_t version;          /**< PLIANT_ABI_VERSION */
  uint32_t config_size;      /**< sizeof(pliant_config_t) */
  uint32_t guard_input_size; /**< sizeof(pliant_guard_input_t) */
  uint32_t verdict_size;     /**< sizeof(pliant_verdict_t) */
  uint32_t estimate_size;    /**< sizeof(pliant_estimate_t) */
  uint32_t deformation_size; /**< sizeof(pliant_deformation_t) */
  uint32_t counters_size;    /**< sizeof(pliant_counters_t) */
  uint32_t info_size;        /**< sizeof(pliant_info_t) */
} pliant_abi_t;

/* ============================================================================================
 * Status codes
 * ========================================================================================== */

typedef enum pliant_status_e {
  PLIANT_OK = 0,
  /** Not an error: the call did its work but no usable observation was available (the
   *  tracker predicted the frame from the model; the estimator stepped without scoring).
   *  Counted in the component's counters. */
  PLIANT_NO_OBSERVATIONS = 1,
  PLIANT_ERROR_NULL_ARGUMENT = 2,       /**< a required pointer is NULL */
  PLIANT_ERROR_INVALID_ARGUMENT = 3,    /**< a size, count, id, option or range is wrong */
  PLIANT_ERROR_NON_FINITE = 4,          /**< NaN or infinity where a finite number is required */
  PLIANT_ERROR_STAMP_ORDER = 5,         /**< a frame stamp not after the previous frame's */
  PLIANT_ERROR_ABI_MISMATCH = 6,        /**< the caller was built against another pliant.h */
  PLIANT_ERROR_MEMORY_TOO_SMALL = 7,    /**< the block is smaller than pliant_workspace_size */
  PLIANT_ERROR_NOT_INITIALIZED = 8,     /**< the instance was never initialised, or init failed */
  PLIANT_ERROR_BAD_STATE = 9,           /**< the call is out of order (e.g. step with no frame) */
  PLIANT_ERROR_DISABLED = 10,           /**< the component (estimator, guard) is disabled */
  PLIANT_ERROR_INVALID_MASS = 11,       /**< a particle mass is not finite and > 0 */
  PLIANT_ERROR_DUPLICATE_REST = 12,     /**< two particles share a rest position */
  PLIANT_ERROR_DEGENERATE_CLUSTER = 13, /**< a cluster has a single member */
  PLIANT_ERROR_NO_FREE_PARTICLES = 14,  /**< every particle is fixed or drivable */
  PLIANT_ERROR_INTERNAL = 15,           /**< an unexpected result inside the library (a bug) */
  PLIANT_STATUS_COUNT = 16
} pliant_status_t;

/** True for a status that means the call was refused (nothing changed). */
#define PLIANT_IS_ERROR(status) ((status) >= PLIANT_ERROR_NULL_ARGUMENT)

/** Short, stable name ("ok", "error_null_argument", ...); "unknown" outside the enum. */
const char* pliant_status_name(pliant_status_t status);

/** Replaces the handler of violated internal invariants (programming errors inside the
 *  library, never bad input: bad input yields a status). The default calls abort(). In a
 *  controller the handler should put the machine in a safe state and not return. NULL restores
 *  the default. Not thread-safe: call once at start-up. */
typedef void (*pliant_assert_handler_t)(const char* expression, const char* file, int line);
void pliant_set_assert_handler(pliant_assert_handler_t handler);

/* ============================================================================================
 * Configuration
 * ========================================================================================== */

/* Cluster layouts (pliant_cluster_config_t.layout). */
#define PLIANT_CLUSTERS_RADIUS 0U      /**< per particle: all within radius_factor x median NN distance */
#define PLIANT_CLUSTERS_K_NEAREST 1U   /**< per particle: itself and its k nearest neighbours */
#define PLIANT_CLUSTERS_GRID_BLOCKS 2U /**< every block window of a particle grid, stride 1 */

typedef struct pliant_cluster_config_s {
  uint8_t layout;       /**< PLIANT_CLUSTERS_*; default RADIUS (the project's MSM default) */
  double radius_factor; /**< RADIUS: > 0, default 1.5 */
  int32_t k;            /**< K_NEAREST: 1..64, default 8 */
  /** GRID_BLOCKS: id = (layer * grid_rows + row) * grid_cols + col and
   *  grid_cols * grid_rows * grid_layers == particle_count; blocks default 3 x 2 x 1. */
  int32_t grid_cols, grid_rows, grid_layers;
  int32_t block_cols, block_rows, block_layers;
} pliant_cluster_config_t;

typedef struct pliant_msm_config_s {
  double msm_alpha;          /**< (0, 1], default 1 */
  double msm_beta;           /**< [0, 1]: the tracker's initial prior, default 0.5 */
  double gravity[3];         /**< m/s^2 in the object frame (z ignored in 2D), default 0 */
  double velocity_damping;   /**< 1/s, >= 0, default 0 */
  double driven_mass_factor; /**< mass multiplier of drivable particles, > 0, default 1 */
} pliant_msm_config_t;

typedef struct pliant_tracker_config_s {
  double tukey_c;                /**< > 0, default 4.685 (robust-scale units) */
  double min_residual_scale;     /**< m, >= 0; set to the observation noise sd; 0: 1e-3 x spacing */
  double observation_gain;       /**< (0, 1], default 1 */
  int32_t projection_iterations; /**< 0..64, default 2 */
  int32_t max_unobserved_frames; /**< >= 1, default 30: frames without observation before "lost" */
} pliant_tracker_config_t;

typedef struct pliant_estimator_config_s {
  bool enabled;       /**< default true; false: no estimator memory, update_estimate refused */
  int32_t candidates; /**< K >= 3 msm_beta candidates on [0, 1] per model form, default 11 */
  /** A in [1, 8] msm_alpha rows, uniform on [alpha_min, 1]; default 3. 1: the msm config's
   *  alpha is held. The form other than (alpha 1, one step) answers only when the frames
   *  determine it (BIC); see pliant_estimate_t.form_fitted. */
  int32_t alpha_candidates;
  double alpha_min;        /**< (0, 1), lowest msm_alpha row when A >= 2, default 0.3 */
  int32_t step_candidates; /**< S in [1, 4]: rows at 1, 2, .., 2^(S-1) MSM steps per frame; default 1 */
  double forgetting;       /**< (0, 1] per-frame weight of past residuals, default 1 */
  /** true (default): after each estimate whose sd is finite and <= feed_back_max_std, the
   *  tracker's prior msm_beta is set to the estimate. */
  bool feed_back_beta;
  double feed_back_max_std; /**< default 0.1 */
  /** The quasi-static row (ABI 3): 0 (default) leaves it out; M in [1, 4096] adds K candidates
   *  relaxed towards equilibrium every frame with at most M MSM iterations each, for objects
   *  loaded slowly enough to stay near equilibrium (pliant_estimate_t.steps_per_frame is 0 when
   *  it answers). It costs up to K x M MSM steps per frame. */
  int32_t equilibrium_iterations;
  double equilibrium_tolerance; /**< > 0, x model spacing: relaxed when no particle moves more; default 1e-4 */
} pliant_estimator_config_t;

/* Verdicts (pliant_verdict_t.verdict, fault_verdict[], uncertain_estimate_verdict). */
#define PLIANT_VERDICT_OK 0U    /**< continue; close no further than safe_width_m */
#define PLIANT_VERDICT_LIMIT 1U /**< hold: close no further, do not raise the force command */
#define PLIANT_VERDICT_STOP 2U  /**< execute stop_action */

/* Stop actions. */
#define PLIANT_STOP_FREEZE 0U /**< stop all jaw motion, keep the current position command */
#define PLIANT_STOP_OPEN 1U   /**< open to at least the contact width (release the squeeze) */

/* Guard input sources (index of fault_verdict[], bit of pliant_verdict_t.fault_sources). */
#define PLIANT_SOURCE_GRIPPER 0U
#define PLIANT_SOURCE_WRENCH 1U
#define PLIANT_SOURCE_CAMERA 2U
#define PLIANT_SOURCE_ESTIMATE 3U
#define PLIANT_SOURCE_CLOCK 4U
#define PLIANT_GUARD_SOURCE_COUNT 5U

/* Grip force source (pliant_guard_config_t.force_source). */
#define PLIANT_FORCE_SENSOR 0U        /**< gripper.force_n */
#define PLIANT_FORCE_MOTOR_CURRENT 1U /**< current_gain_n_per_a x (gripper.current_a - current_offset_a) */

/** The grasp guard: the object's limits, the jaws, and how faults are handled. Every field has
 *  the default pliant_config_init_default gives; see the core's grasp_guard.hpp for the
 *  algorithm. Widths are pad-to-pad openings; closure = contact width - width. */
typedef struct pliant_guard_config_s {
  bool enabled; /**< default true; false: no guard memory, guard calls refused */

  /* --- the object's limits ------------------------------------------------------------- */
  double max_strain;        /**< largest cluster principal strain, > 0 (+inf: none); 0.1 */
  double max_indentation_m; /**< closure limit, > 0; default +inf (none) */
  double max_force_n;       /**< hard grip-force limit, finite > 0; default 10 */
  double nominal_force_n;   /**< allowed force without slip, (0, max]; NaN (default): max */

  /* --- jaws ------------------------------------------------------------------------------ */
  /** Squeeze direction in the object frame, jaw A -> jaw B; normalised at init; required
   *  (default all zero is refused). z is ignored in 2D. */
  double squeeze_axis[3];
  /** Particles touching each jaw at first contact (read during init only). NULL / 0: those
   *  within contact_band x spacing of the extreme rest positions along the axis. */
  const int32_t* jaw_a_ids;
  uint32_t jaw_a_count;
  const int32_t* jaw_b_ids;
  uint32_t jaw_b_count;
  double contact_band; /**< default 0.25 */

  /* --- contact ------------------------------------------------------------------------- */
  double contact_width_m;         /**< width at first contact; NaN (default): detected by force */
  double contact_force_n;         /**< detection force, default 0.5 */
  double contact_width_tolerance; /**< detected width vs model extent, fraction; default 0.5 */
  double max_width_m;             /**< widths outside [0, max] are invalid; default 0.5 */

  /* --- grip force ---------------------------------------------------------------------- */
  uint8_t force_source;        /**< PLIANT_FORCE_*; default SENSOR */
  double current_gain_n_per_a; /**< MOTOR_CURRENT: finite > 0 */
  double current_offset_a;

  /* --- freshness, s ------------------------------------------------------------------- */
  double gripper_timeout_s;      /**< default 0.02 */
  double wrench_timeout_s;       /**< default 0.02 */
  double camera_timeout_s;       /**< default 0.1 */
  double estimate_timeout_s;     /**< default 0.5 */
  double cycle_timeout_s;        /**< longest gap between guard cycles, default 0.02 */
  double clock_tolerance_s;      /**< how far a stamp may lie in the future, default 0.002 */
  int32_t wrench_frozen_samples; /**< bit-identical wrench samples meaning frozen; 0 (default): off */

  /* --- status words: set bits are faults -------------------------------------------- */
  /* Defaults: the HAL's status words plus the stream monitor's flags 17-21 (0x003e0000),
   * docs/grasp_guard.md "Status words". */
  uint32_t gripper_fault_mask; /**< default 0x003eff00: the fault code byte 8-15 (Robotiq gFLT | kFLT << 4);
                                    activated, moving, object detected, at target are states */
  uint32_t wrench_fault_mask;  /**< default 0x003e18fe (ATI NETCANOEM status bits 1-7, 11, 12) */
  uint32_t camera_fault_mask;  /**< default 0x003e0001: the device marked the frame unusable */

  /* --- verdicts and hysteresis ------------------------------------------------------- */
  /** Verdict of a fault per PLIANT_SOURCE_* (LIMIT or STOP). Defaults: gripper, wrench and
   *  clock STOP; camera and estimate LIMIT. */
  uint8_t fault_verdict[PLIANT_GUARD_SOURCE_COUNT];
  uint8_t uncertain_estimate_verdict; /**< default OK (reported only) */
  uint8_t exceeded_stop_action;       /**< stop for an exceeded limit; default OPEN */
  uint8_t fault_stop_action;          /**< stop for a fault; default FREEZE */
  bool latch_stop;                    /**< STOP persists until acknowledged; default false */
  double hysteresis_margin;           /**< [0, 1), default 0.05 */
  int32_t clear_samples;              /**< >= 1, default 5 */
  double stop_overshoot;              /**< >= 0, default 0.1: STOP at limit x (1 + this) */

  /* --- the estimate --------------------------------------------------------------------- */
  double confidence_k; /**< interval half-width in sd, >= 0, default 2 */
  double max_beta_std; /**< > 0, default 0.15 */

  /* --- slip cue (PR2 gripper controller) -------------------------------------------- */
  double slip_cutoff_hz;        /**< default 5 */
  double slip_ratio;            /**< default 0.007 */
  double slip_floor_n;          /**< default 0.048 */
  double slip_ceiling_n;        /**< default 0.2 */
  double slip_force_rate_per_s; /**< default 2 */

  /* --- force model ------------------------------------------------------------------- */
  double force_fit_spacing_m;       /**< default 1e-4 */
  double force_fit_forgetting;      /**< (0, 1], default 0.7 */
  double force_model_min_closure_m; /**< default 2e-4 */

  /* --- prediction table (built by pliant_init: this is what makes init slow) -------- */
  int32_t prediction_beta_points;    /**< >= 2, default 11 */
  int32_t prediction_closure_points; /**< >= 2, default 32 */
  int32_t prediction_refine_steps;   /**< >= 1, default 8 */
  double prediction_max_closure_m;   /**< NaN (default): from max_strain and the extent */
  int32_t relax_max_iterations;      /**< >= 1, default 3000 */
  double relax_tolerance;            /**< x spacing, default 1e-6 */
} pliant_guard_config_t;

/** The object and every component's options. Arrays are read during pliant_workspace_size and
 *  pliant_init only (copied into the block); the caller may free them afterwards. */
typedef struct pliant_config_s {
  pliant_abi_t abi;            /**< set by pliant_config_init_default; do not touch */
  uint32_t dim;                /**< 2 or 3 (default 3) */
  uint32_t particle_count;     /**< N >= 2 */
  const float* rest_positions; /**< [N * dim] m, the undeformed object (required) */
  const float* masses;         /**< [N] kg, finite > 0; NULL (default): 1 for all */
  const uint8_t* fixed;        /**< [N] 1 = pinned at rest; NULL (default): none */
  const int32_t* drivable_ids; /**< particles the tool contact may drive; NULL / 0: none */
  uint32_t drivable_count;     /**< <= N */
  pliant_cluster_config_t clusters;
  pliant_msm_config_t msm;
  pliant_tracker_config_t tracker;
  pliant_estimator_config_t estimator;
  pliant_guard_config_t guard;
} pliant_config_t;

/** Fills *config with the defaults documented above and the ABI stamp of the caller's
 *  header. Use the inline pliant_config_init_default() below, not this, directly.
 *  Errors: NULL_ARGUMENT, ABI_MISMATCH (nothing written). */
pliant_status_t pliant_config_init_default_checked(pliant_config_t* config, const pliant_abi_t* caller_abi);

/* ============================================================================================
 * Per-cycle guard input and output
 * ========================================================================================== */

typedef struct pliant_gripper_sample_s {
  double stamp_s;       /**< the sample's time */
  double width_m;       /**< pad-to-pad opening */
  double force_n;       /**< grip force (PLIANT_FORCE_SENSOR) */
  double current_a;     /**< motor current (PLIANT_FORCE_MOTOR_CURRENT) */
  uint32_t status_bits; /**< driver status word; bits in gripper_fault_mask are faults */
  bool valid;           /**< false: the driver has no good sample (a fault) */
  bool bus_off;
  bool timeout; /**< the driver timed out reading the gripper */
} pliant_gripper_sample_t;

typedef struct pliant_wrench_sample_s {
  double stamp_s;
  double wrench[6]; /**< Fx Fy Fz (N), Tx Ty Tz (N m) in the sensor frame */
  uint32_t status_bits;
  bool valid;
  bool bus_off;
  bool timeout;
} pliant_wrench_sample_t;

/* Where the guard takes a deformation or estimate sample from. */
#define PLIANT_SOURCE_BRIDGE 0U /**< this instance's last tracked frame / last estimate (default) */
#define PLIANT_SOURCE_CALLER 1U /**< the values in the input struct */

typedef struct pliant_deformation_sample_s {
  /** PLIANT_SOURCE_BRIDGE: stamp_s, strain and valid are taken from the last stepped frame
   *  (its stamp, the strain measured on the tracked positions, valid when measured; no frame
   *  yet: not valid, a camera fault); status_bits, bus_off and timeout are still the
   *  caller's (the camera driver's flags). PLIANT_SOURCE_CALLER: all fields are the caller's. */
  uint8_t source;
  double stamp_s;       /**< capture time of the frame */
  double strain;        /**< largest cluster principal strain, >= 0 */
  uint32_t status_bits; /**< bits in camera_fault_mask are faults */
  bool valid;
  bool bus_off;
  bool timeout;
} pliant_deformation_sample_t;

typedef struct pliant_estimate_sample_s {
  /** PLIANT_SOURCE_BRIDGE: the estimator's latest estimate (stamped with its frame; before
   *  the first estimator frame, or with the estimator disabled: not valid, an estimate fault).
   *  PLIANT_SOURCE_CALLER: the fields below. */
  uint8_t source;
  double stamp_s;
  double msm_beta;     /**< [0, 1] */
  double msm_beta_std; /**< >= 0; +inf: not yet identifiable (not a fault) */
  bool valid;
} pliant_estimate_sample_t;

typedef struct pliant_guard_input_s {
  double now_s; /**< this cycle's time on the monotonic clock */
  pliant_gripper_sample_t gripper;
  pliant_wrench_sample_t wrench;
  pliant_deformation_sample_t deformation;
  pliant_estimate_sample_t estimate;
} pliant_guard_input_t;

/** Sets every time and value of *input to NaN, every flag to false, status words to 0 and both
 *  sources to PLIANT_SOURCE_BRIDGE. Use the inline pliant_guard_input_init() below.
 *  Errors: NULL_ARGUMENT, ABI_MISMATCH (size differs; nothing written). Real-time safe. */
pliant_status_t pliant_guard_input_init_checked(pliant_guard_input_t* input, size_t input_size);

/* Reasons (pliant_verdict_t.reason; bit (1 << reason) in reasons). Same values as the core's
 * GuardReason and the telemetry verdict message. Order = priority within a verdict. */
#define PLIANT_REASON_NONE 0U
#define PLIANT_REASON_FORCE_EXCEEDED 1U       /**< stop: force >= max_force_n x (1 + overshoot) */
#define PLIANT_REASON_STRAIN_EXCEEDED 2U      /**< stop: strain >= max_strain x (1 + overshoot) */
#define PLIANT_REASON_INDENTATION_EXCEEDED 3U /**< stop: closure >= max_indentation_m x (1 + overshoot) */
#define PLIANT_REASON_NOT_CONFIGURED 4U       /**< stop: no guard, or contact width contradicts the model */
#define PLIANT_REASON_NAN_INPUT 5U
#define PLIANT_REASON_INVALID_INPUT 6U /**< valid false, out of range, stamp in future/backwards */
#define PLIANT_REASON_SENSOR_FAULT 7U
#define PLIANT_REASON_BUS_OFF 8U
#define PLIANT_REASON_TIMEOUT 9U /**< driver timeout, or guard not called in cycle_timeout_s */
#define PLIANT_REASON_STALE_GRIPPER 10U
#define PLIANT_REASON_STALE_WRENCH 11U /**< also: frozen (bit-identical) wrench */
#define PLIANT_REASON_STALE_CAMERA 12U
#define PLIANT_REASON_STALE_ESTIMATE 13U
#define PLIANT_REASON_FORCE_LIMIT 14U        /**< limit: force >= allowed_force_n */
#define PLIANT_REASON_STRAIN_LIMIT 15U       /**< limit: strain >= max_strain */
#define PLIANT_REASON_INDENTATION_LIMIT 16U  /**< limit: closure >= max_indentation_m */
#define PLIANT_REASON_PREDICTED_STRAIN 17U   /**< limit: closure >= the MSM-predicted safe closure */
#define PLIANT_REASON_ESTIMATE_UNCERTAIN 18U /**< msm_beta_std >= max_beta_std */
#define PLIANT_REASON_COUNT 19U

/** The guard's answer for one cycle. Doubles are NaN where not known (e.g. before contact). */
typedef struct pliant_verdict_s {
  uint8_t verdict;       /**< PLIANT_VERDICT_* */
  uint8_t reason;        /**< dominant PLIANT_REASON_*; NONE when OK */
  uint8_t stop_action;   /**< PLIANT_STOP_*: what STOP means this cycle */
  uint8_t fault_sources; /**< bit (1 << PLIANT_SOURCE_*) per source with an active fault */
  uint32_t reasons;      /**< bit (1 << reason) per active reason */
  bool in_contact;
  bool slip; /**< slip cue active this cycle */
  double contact_width_m;
  double closure_m;             /**< contact width - width, >= 0 (0 before contact) */
  double force_n;               /**< grip force used this cycle */
  double strain;                /**< measured strain used this cycle */
  double allowed_force_n;       /**< nominal, raised by slip, <= max_force_n */
  double beta_low, beta_high;   /**< msm_beta interval of the prediction */
  double predicted_strain;      /**< at the current closure, worst over the interval */
  double strain_safe_closure_m; /**< largest closure with predicted strain <= max_strain */
  double force_safe_closure_m;  /**< closure where the predicted force reaches allowed_force_n */
  double safe_closure_m;        /**< min of the above and max_indentation_m */
  double safe_width_m;          /**< contact width - safe_closure_m: close no further */
  double predicted_force_n;     /**< force predicted at safe_closure_m */
  double stiffness_n_per_m;     /**< slope of the force model */
  double slip_force_n;          /**< high-passed wrist force magnitude */
} pliant_verdict_t;

/* ============================================================================================
 * Results and counters
 * ========================================================================================== */

/* Per-particle track status (pliant_get_tracked); same values as the telemetry message. */
#define PLIANT_TRACK_OBSERVED 0U  /**< corrected toward a usable observation this frame */
#define PLIANT_TRACK_PREDICTED 1U /**< no usable observation this frame: follows the model */
#define PLIANT_TRACK_LOST 2U      /**< no usable observation for > max_unobserved_frames */

typedef struct pliant_estimate_s {
  double stamp_s;           /**< stamp of the last frame the estimator used; NaN before */
  double msm_beta;          /**< [0, 1] */
  double msm_beta_std;      /**< +inf until the residual curve has a positive curvature */
  double rms;               /**< rms residual of the best candidate, m */
  double msm_alpha;         /**< msm_alpha of the answering model form */
  uint32_t steps_per_frame; /**< MSM steps per frame of the answering model form; 0: the quasi-static row */
  bool form_fitted;         /**< true: the frames determined a form other than alpha 1, one step */
  uint32_t frames;          /**< frames the estimator used since init / reset */
  bool unique_minimum;      /**< the residual curve has one basin */
  bool valid;               /**< frames > 0 and msm_beta_std finite */
  bool fed_back;            /**< this estimate was fed to the tracker's prior */
  double tracker_msm_beta;  /**< the tracker's current prior msm_beta */
} pliant_estimate_t;

typedef struct pliant_deformation_s {
  double stamp_s;  /**< the frame's stamp; NaN before the first frame */
  double strain;   /**< largest cluster principal strain; NaN if not measured */
  int32_t cluster; /**< the cluster holding it, -1 if none */
  int32_t clusters_measured;
  int32_t clusters_skipped; /**< clusters with a lost particle */
  bool valid;               /**< measured on the last frame */
} pliant_deformation_t;

/* Counter ids of the telemetry counters message (docs/telemetry.md). */
#define PLIANT_COUNTER_TRACKER_FRAMES 1U
#define PLIANT_COUNTER_TRACKER_FRAMES_REJECTED 2U
#define PLIANT_COUNTER_OBSERVATIONS_USED 3U
#define PLIANT_COUNTER_OUTLIERS 4U
#define PLIANT_COUNTER_PARTICLES_LOST 5U
#define PLIANT_COUNTER_ESTIMATOR_FRAMES 6U
#define PLIANT_COUNTER_ESTIMATOR_FRAMES_REJECTED 7U
#define PLIANT_COUNTER_GUARD_CYCLES 8U
#define PLIANT_COUNTER_GUARD_LIMIT_CYCLES 9U
#define PLIANT_COUNTER_GUARD_STOP_CYCLES 10U
#define PLIANT_COUNTER_GUARD_SLIP_CYCLES 11U
#define PLIANT_COUNTER_GUARD_INPUTS_REFUSED 12U
#define PLIANT_COUNTER_GUARD_STALE_CYCLES 13U
#define PLIANT_COUNTER_TELEMETRY_NOT_SENT 14U
#define PLIANT_COUNTER_CALLS_REJECTED 15U
#define PLIANT_COUNTER_ID_COUNT 15U

/* Calls, as recorded in pliant_counters_t.last_rejected_call. */
#define PLIANT_CALL_NONE 0U
#define PLIANT_CALL_PUSH_OBSERVATIONS 1U
#define PLIANT_CALL_PUSH_TOOL_CONTACT 2U
#define PLIANT_CALL_STEP_TRACKER 3U
#define PLIANT_CALL_GET_TRACKED 4U
#define PLIANT_CALL_UPDATE_ESTIMATE 5U
#define PLIANT_CALL_GET_ESTIMATE 6U
#define PLIANT_CALL_GET_DEFORMATION 7U
#define PLIANT_CALL_GUARD_UPDATE 8U
#define PLIANT_CALL_RESET_GRASP 9U
#define PLIANT_CALL_ACKNOWLEDGE_STOP 10U
#define PLIANT_CALL_GET_COUNTERS 11U
#define PLIANT_CALL_GET_INFO 12U
#define PLIANT_CALL_RESET_GRASP_GUARD 13U
#define PLIANT_CALL_EMIT_TELEMETRY 14U
#define PLIANT_CALL_TELEMETRY_BYTES 15U

/** Monotonic counters (wrap at 2^32), since pliant_init. Fields 1-15 are the telemetry
 *  counter ids; the rest are details. */
typedef struct pliant_counters_s {
  uint32_t tracker_frames;            /**< 1: frames the tracker accepted */
  uint32_t tracker_frames_rejected;   /**< 2: frames the tracker refused */
  uint32_t observations_used;         /**< 3: particle observations used with weight > 0 */
  uint32_t outliers;                  /**< 4: finite observations given weight 0 */
  uint32_t particles_lost;            /**< 5: transitions of a particle to lost */
  uint32_t estimator_frames;          /**< 6: frames the estimator used */
  uint32_t estimator_frames_rejected; /**< 7: frames the estimator refused */
  uint32_t guard_cycles;              /**< 8 */
  uint32_t guard_limit_cycles;        /**< 9 */
  uint32_t guard_stop_cycles;         /**< 10 */
  uint32_t guard_slip_cycles;         /**< 11 */
  uint32_t guard_inputs_refused;      /**< 12: sum of guard_refused[] */
  uint32_t guard_stale_cycles;        /**< 13: sum of guard_stale[] */
  uint32_t telemetry_not_sent;        /**< 14: telemetry packets not emitted (no room) */
  uint32_t calls_rejected;            /**< 15: calls refused with an error status */
  /* details */
  uint32_t tracker_unobserved;                       /**< particle-frames without a finite observation */
  uint32_t tracker_empty_frames;                     /**< frames with no usable observation */
  uint32_t estimator_empty_frames;                   /**< estimator frames with no particle to score */
  uint32_t estimator_frames_skipped;                 /**< stepped frames never given to the estimator */
  uint32_t frames_replaced;                          /**< pushed frames overwritten before being stepped */
  uint32_t strain_unmeasured;                        /**< stepped frames whose strain could not be measured */
  uint32_t guard_refused[PLIANT_GUARD_SOURCE_COUNT]; /**< per PLIANT_SOURCE_* */
  uint32_t guard_stale[PLIANT_GUARD_SOURCE_COUNT];   /**< per PLIANT_SOURCE_* */
  uint8_t last_rejected_status;                      /**< pliant_status_t of the last refused call */
  uint8_t last_rejected_call;                        /**< PLIANT_CALL_* of the last refused call */
} pliant_counters_t;

/** The value of telemetry counter `id` (1..PLIANT_COUNTER_ID_COUNT) in *counters.
 *  Errors: NULL_ARGUMENT, INVALID_ARGUMENT (unknown id). Real-time safe. */
pliant_status_t pliant_counter_by_id(const pliant_counters_t* counters, uint16_t id, uint32_t* out_value);

/** What pliant_init built. */
typedef struct pliant_info_s {
  uint32_t dim;
  uint32_t particle_count;
  uint32_t cluster_count;
  uint32_t drivable_count;
  uint32_t scalar_bytes;  /**< 8: computes in double, 4: in float */
  size_t workspace_bytes; /**< what pliant_workspace_size asked for */
  double spacing_m;       /**< median nearest-neighbour distance of the rest shape */
  bool estimator_enabled;
  bool guard_enabled;
  double guard_extent_m;                 /**< the object's extent along the squeeze axis */
  int32_t guard_unconverged_relaxations; /**< init relaxations that hit relax_max_iterations */
  int64_t guard_relaxation_steps;        /**< MSM steps pliant_init spent on the prediction table */
} pliant_info_t;

/* ============================================================================================
 * Lifecycle
 * ========================================================================================== */

/** The instance: opaque, it lives inside the caller's block. */
typedef struct pliant_s pliant_t;

/** Bytes of memory pliant_init needs for *config, at any alignment of the block. Exact when
 *  the library computes in float; in double it bounds the two MSM models by twice their float
 *  size (a few percent of the total more than init uses).
 *  Validates the configuration as far as possible without building it (ABI, dim, counts,
 *  pointers, ids, options, ranges, finiteness, masses). A rest shape the core cannot build
 *  (duplicate positions, a single-member cluster) is INVALID_ARGUMENT here; pliant_init names
 *  the reason. *out_bytes is 0 on any error. Errors: NULL_ARGUMENT, ABI_MISMATCH,
 *  INVALID_ARGUMENT, NON_FINITE, INVALID_MASS. O(N^2) (it counts cluster memberships); not
 *  real-time; uses no memory. */
pliant_status_t pliant_workspace_size(const pliant_config_t* config, size_t* out_bytes);

/** Builds everything inside [memory, memory + size) and sets *out_instance to the instance
 *  (which also lives in the block). The caller owns the block and must keep it, unmoved, for
 *  as long as the instance is used; there is no deinit (stop using it, reuse the memory).
 *  Calling init again on the same block replaces the instance. On error *out_instance is set to
 *  NULL (when out_instance is not NULL); an instance the block held before is still usable when
 *  the config or the size was refused before building (NULL_ARGUMENT, ABI_MISMATCH, NON_FINITE,
 *  MEMORY_TOO_SMALL, INVALID_ARGUMENT from validation), and gone otherwise: do not rely on it.
 *  SLOW (see FOOTPRINT AND TIMING): it builds the guard's prediction table. Not real-time.
 *  Errors: NULL_ARGUMENT, ABI_MISMATCH, INVALID_ARGUMENT, NON_FINITE, MEMORY_TOO_SMALL,
 *  INVALID_MASS, DUPLICATE_REST, DEGENERATE_CLUSTER, NO_FREE_PARTICLES (the estimator needs a
 *  free particle), INTERNAL. */
pliant_status_t pliant_init(void* memory, size_t size, const pliant_config_t* config, pliant_t** out_instance);

/** What init built. Real-time safe, O(1). Errors: NULL_ARGUMENT, NOT_INITIALIZED. */
pliant_status_t pliant_get_info(pliant_t* instance, pliant_info_t* out);

/* ============================================================================================
 * Per camera frame (frame group)
 * ========================================================================================== */

/** Stages a frame: copies the observed positions (and confidences) into the instance and
 *  clears the pending tool contact. A frame pushed and not yet stepped is replaced (counted in
 *  frames_replaced).
 *  stamp_s: the frame's capture time: finite and after the last stepped frame's stamp.
 *  positions: [N * dim] m in the object frame; a particle with a non-finite coordinate is
 *    unobserved; NULL: nothing observed this frame (the tracker predicts it).
 *  confidence: optional [N] in [0, 1]; non-finite or <= 0: unobserved; NULL: 1 for all.
 *  Errors: NULL_ARGUMENT (instance), NOT_INITIALIZED, NON_FINITE (stamp), STAMP_ORDER.
 *  Real-time safe, O(N). */
pliant_status_t pliant_push_observations(pliant_t* instance, double stamp_s, const float* positions,
                                         const float* confidence);

/** Sets the tool contact of the pending frame: particle ids[k] (a drivable id) is driven to
 *  targets[k * dim .. + dim) (m, object frame) during this frame's step. Replaces any contact
 *  set for this frame; count 0 (ids, targets may be NULL) clears it. Call after
 *  pliant_push_observations.
 *  Errors: NULL_ARGUMENT, NOT_INITIALIZED, BAD_STATE (no pending frame), INVALID_ARGUMENT
 *  (count > drivable_count, an id out of range, not drivable or repeated), NON_FINITE.
 *  Real-time safe, O(count + N). */
pliant_status_t pliant_push_tool_contact(pliant_t* instance, const int32_t* ids, const float* targets, uint32_t count);

/** Runs the tracker on the pending frame: one MSM step of dt_s (seconds since the previous
 *  frame, normally the stamp difference; finite > 0) driven by the tool contact, robust
 *  correction toward the observations, shape-matching regularisation of the rest. Then, with
 *  the guard enabled, measures the frame's strain (the deformation sample). A call refused for
 *  its dt keeps the pending frame; once the tracker has run, the frame is consumed.
 *  Returns OK, NO_OBSERVATIONS (predicted only; counted), or errors: NULL_ARGUMENT,
 *  NOT_INITIALIZED, BAD_STATE (no pending frame), NON_FINITE / INVALID_ARGUMENT (dt).
 *  Real-time safe: one MSM step + O(N) (+ O(memberships) for the strain). */
pliant_status_t pliant_step_tracker(pliant_t* instance, double dt_s);

/** Copies the tracked state of the last stepped frame (the rest shape before any):
 *  positions [N * dim] floats, status [N] PLIANT_TRACK_* bytes; either may be NULL, not both.
 *  particle_capacity: N of the caller's arrays, >= particle_count. out_frame_index (optional):
 *  frames the tracker accepted since init or reset.
 *  Errors: NULL_ARGUMENT, NOT_INITIALIZED, INVALID_ARGUMENT (capacity). Real-time safe, O(N). */
pliant_status_t pliant_get_tracked(pliant_t* instance, float* positions, uint8_t* status, uint32_t particle_capacity,
                                   uint32_t* out_frame_index);

/** Feeds the last stepped frame to the online estimator: its K MSM candidates advance by the
 *  frame's dt with its tool contact and are scored against the tracked positions of particles
 *  observed in that frame (predicted and lost ones, which only echo the tracker's own prior,
 *  are unobserved here). Call once after every pliant_step_tracker; a frame not given to the
 *  estimator is counted (estimator_frames_skipped) and its time is added to the next
 *  estimator step. With feed_back_beta, a confident estimate becomes the tracker's prior.
 *  Returns OK, NO_OBSERVATIONS (stepped, nothing scored; counted), or errors: NULL_ARGUMENT,
 *  NOT_INITIALIZED, DISABLED, BAD_STATE (no new stepped frame). Real-time safe,
 *  K x A x (2^S - 1) MSM steps. */
pliant_status_t pliant_update_estimate(pliant_t* instance);

/** The current estimate. Errors: NULL_ARGUMENT, NOT_INITIALIZED, DISABLED. Real-time, O(K A S). */
pliant_status_t pliant_get_estimate(pliant_t* instance, pliant_estimate_t* out);

/** The strain measured on the last stepped frame (what PLIANT_SOURCE_BRIDGE gives the guard).
 *  Errors: NULL_ARGUMENT, NOT_INITIALIZED, DISABLED (guard disabled). Real-time, O(1). */
pliant_status_t pliant_get_deformation(pliant_t* instance, pliant_deformation_t* out);

/* ============================================================================================
 * Per control cycle (cycle group)
 * ========================================================================================== */

/** One guard cycle: maps *input (with the bridge's own deformation and estimate samples where
 *  their source is PLIANT_SOURCE_BRIDGE) to the core grasp guard and writes its verdict.
 *  Returns OK whatever the verdict. On ANY error *out (when not NULL) is a STOP verdict with
 *  reason NOT_CONFIGURED and stop action FREEZE, so a firmware that only reads the verdict
 *  still fails safe. Errors: NULL_ARGUMENT, NOT_INITIALIZED, DISABLED, INVALID_ARGUMENT (a
 *  source field that is not a PLIANT_SOURCE_*). Bad sensor values are NOT errors: they are
 *  faults in the verdict (and counted in guard_refused / guard_stale).
 *  Real-time safe, O(prediction_beta_points). */
pliant_status_t pliant_guard_update(pliant_t* instance, const pliant_guard_input_t* input, pliant_verdict_t* out);

/** A new grasp of the guard only: forgets contact, force fit, slip and measured-limit reasons,
 *  clears a latched stop (fault hysteresis is kept). Errors: NULL_ARGUMENT, NOT_INITIALIZED,
 *  DISABLED. Real-time safe. */
pliant_status_t pliant_reset_grasp_guard(pliant_t* instance);

/** Clears a STOP held by latch_stop (it re-latches next cycle if its cause persists).
 *  Errors: NULL_ARGUMENT, NOT_INITIALIZED, DISABLED. Real-time safe. */
pliant_status_t pliant_acknowledge_stop(pliant_t* instance);

/* ============================================================================================
 * Both groups
 * ========================================================================================== */

/** A new grasp of the same object, released and back at its rest shape: the tracker returns
 *  to the rest shape with the configured prior msm_beta, the estimator forgets its evidence
 *  (its sample becomes msm_beta unknown: sd +inf), the guard is reset as by
 *  pliant_reset_grasp_guard, any pending frame is dropped, and the bridge's deformation sample
 *  is invalid until the next stepped frame (a camera fault for the guard meanwhile: LIMIT by
 *  default, cleared after clear_samples new frames).
 *  Counters are kept; frame stamps must still increase. Errors: NULL_ARGUMENT,
 *  NOT_INITIALIZED. Real-time safe, O(K (N + C)). */
pliant_status_t pliant_reset_grasp(pliant_t* instance);

/** Copies the counters. Errors: NULL_ARGUMENT, NOT_INITIALIZED. Real-time safe, O(1). */
pliant_status_t pliant_get_counters(pliant_t* instance, pliant_counters_t* out);

/* ============================================================================================
 * Telemetry (docs/telemetry.md; the codec is pliant_telemetry.h)
 * ========================================================================================== */

/* Messages for pliant_emit_telemetry (bits of message_mask). */
#define PLIANT_TELEMETRY_ESTIMATE 0x01U  /**< the current estimate (estimator enabled) */
#define PLIANT_TELEMETRY_VERDICT 0x02U   /**< the last verdict (none before the first cycle) */
#define PLIANT_TELEMETRY_PARTICLES 0x04U /**< the tracked frame, in as many chunks as needed */
#define PLIANT_TELEMETRY_COUNTERS 0x08U  /**< counters with ids 1-15 */
#define PLIANT_TELEMETRY_ALL 0x0FU

/** Bytes pliant_emit_telemetry needs for message_mask: the worst-case COBS size of every frame
 *  it would write now. Errors: NULL_ARGUMENT, NOT_INITIALIZED, INVALID_ARGUMENT (mask bits
 *  beyond PLIANT_TELEMETRY_ALL; particles of an object over 65535 particles). O(1). */
pliant_status_t pliant_telemetry_bytes(pliant_t* instance, uint32_t message_mask, size_t* out_bytes);

/** Encodes the messages of message_mask as telemetry frames (COBS packet + 0x00 each), in the
 *  order estimate, verdict, particles chunks, counters, into buffer[0 .. capacity), stamped
 *  stamp_us (the controller's monotonic clock, microseconds), and sets *written to their total
 *  length: send those bytes as they are. Messages with nothing to report yet (the verdict before
 *  the first guard cycle; the estimate with the estimator disabled) are left out. Every packet
 *  takes the instance's next sequence number. All or nothing: with capacity below
 *  pliant_telemetry_bytes the call writes nothing, returns MEMORY_TOO_SMALL and counts every
 *  packet it would have sent in telemetry_not_sent.
 *  Errors: NULL_ARGUMENT, NOT_INITIALIZED, INVALID_ARGUMENT, MEMORY_TOO_SMALL, INTERNAL.
 *  Reads both call groups (see THREADING). Real-time safe, O(N + written). */
pliant_status_t pliant_emit_telemetry(pliant_t* instance, uint32_t message_mask, uint64_t stamp_us, uint8_t* buffer,
                                      size_t capacity, size_t* written);

/** Short, stable names for logs; "unknown" outside the range. */
const char* pliant_verdict_name(uint8_t verdict);
const char* pliant_reason_name(uint8_t reason);
const char* pliant_source_name(uint8_t source);

/* ============================================================================================
 * Inline helpers: they measure the CALLER's header, which is what makes the ABI check work
 * ========================================================================================== */

/* A cast that is clean under both C and C++ warning sets (-Wold-style-cast). */
#ifdef __cplusplus
#define PLIANT_U32_(value) static_cast<uint32_t>(value)
#else
#define PLIANT_U32_(value) ((uint32_t)(value))
#endif

/** The ABI stamp of the header this translation unit was compiled with. */
static inline pliant_abi_t pliant_abi_of_caller(void) {
  pliant_abi_t abi;
  abi.version = PLIANT_ABI_VERSION;
  abi.config_size = PLIANT_U32_(sizeof(pliant_config_t));
  abi.guard_input_size = PLIANT_U32_(sizeof(pliant_guard_input_t));
  abi.verdict_size = PLIANT_U32_(sizeof(pliant_verdict_t));
  abi.estimate_size = PLIANT_U32_(sizeof(pliant_estimate_t));
  abi.deformation_size = PLIANT_U32_(sizeof(pliant_deformation_t));
  abi.counters_size = PLIANT_U32_(sizeof(pliant_counters_t));
  abi.info_size = PLIANT_U32_(sizeof(pliant_info_t));
  return abi;
}

/** Fills *config with the defaults and this header's ABI stamp. Required before setting
 *  fields: a config not made by it is refused with ABI_MISMATCH. Errors: NULL_ARGUMENT,
 *  ABI_MISMATCH (the library was built from another pliant.h). */
static inline pliant_status_t pliant_config_init_default(pliant_config_t* config) {
  const pliant_abi_t abi = pliant_abi_of_caller();
  return pliant_config_init_default_checked(config, &abi);
}

/** See pliant_guard_input_init_checked. */
static inline pliant_status_t pliant_guard_input_init(pliant_guard_input_t* input) {
  return pliant_guard_input_init_checked(input, sizeof(pliant_guard_input_t));
}

#ifdef __cplusplus
}
#endif

#endif /* PLIANT_H */
