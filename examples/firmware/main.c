/* Example firmware: pliant's grasp guard closing a gripper on a soft block, on a Cortex-M7.
 *
 * Two contexts, as pliant.h (THREADING) describes:
 *   - the control cycle, in the 1 kHz tick interrupt: read the gripper and the wrist sensor, run
 *     the guard, command the jaws by its verdict;
 *   - the frame task, in the main loop, ~30 times a second: push the camera frame and the jaw
 *     contact, step the tracker, update the msm_beta estimate, and hand the strain and the
 *     estimate to the control cycle through a mailbox (PLIANT_SOURCE_CALLER); then queue
 *     telemetry for the UART (estimate and latest verdict every frame; tracked particles and
 *     counters once a second). Frame work may take longer than a tick: the guard keeps its rate
 *     because the tick interrupt preempts it.
 * The sensors are the synthetic squeeze (squeeze.h). The demo closes toward a width that would
 * crush the block, holds where the guard says "no further" for a second, releases, and grasps
 * again.
 *
 * All memory is static: pliant's block is sized at compile time and checked at start-up against
 * pliant_workspace_size. Any failure puts the machine in the safe state.
 */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>

#include "board.h"
#include "pliant.h"
#include "squeeze.h"

/* pliant's memory for this object (24 particles, 3D, defaults, the library computing in double):
 * pliant_workspace_size asks for about 205 KiB. Start-up refuses to run if it is not enough. */
#define WORKSPACE_BYTES (224U * 1024U)
#define CAMERA_PERIOD_TICKS 33U      /* ~30 frames/s */
#define SLOW_TELEMETRY_TICKS 1000U   /* particles and counters once a second */
#define TELEMETRY_BUFFER_BYTES 1024U /* one frame's messages: pliant_telemetry_bytes says ~560 */
#define OPEN_WIDTH_M 0.034           /* jaws open, 4 mm clear of the block */
#define WANTED_WIDTH_M 0.015         /* what the task asks for: would crush the block */
#define HOLD_TICKS 1000U             /* hold at the guard's limit this long, then release */
#define TICK_S (BOARD_TICK_US * 1e-6)

typedef enum {
  PHASE_GRASP,   /* close toward WANTED_WIDTH_M as far as the guard allows */
  PHASE_HOLD,    /* the guard said "no further": stay there */
  PHASE_RELEASE, /* open */
  PHASE_RESET    /* open: the frame task starts a new grasp (pliant_reset_grasp) */
} phase_t;

/* The jaw command: opening (m) and whether it holds a position taken when the guard said
 * "no further". */
typedef struct jaw_command_s {
  double width_m;
  bool holding;
} jaw_command_t;

/* The frame task's results for the control cycle. Written by the frame task inside board_lock,
 * read by the tick interrupt (which the frame task cannot preempt). */
typedef struct mailbox_s {
  pliant_deformation_t deformation;
  pliant_estimate_t estimate;
} mailbox_t;

static uint8_t g_workspace[WORKSPACE_BYTES];
static pliant_t* g_pliant;
static squeeze_t g_squeeze; /* the control cycle moves the jaws; the frame task films them */
static mailbox_t g_mailbox;
static volatile phase_t g_phase = PHASE_GRASP;
static jaw_command_t g_jaw = {OPEN_WIDTH_M, false}; /* control cycle only */

static void on_pliant_assert(const char* expression, const char* file, int line) {
  (void)expression;
  (void)file;
  (void)line;
  board_fail_safe();
}

static void require(pliant_status_t status) {
  if (PLIANT_IS_ERROR(status)) {
    board_fail_safe();
  }
}

static void setup(void) {
  pliant_set_assert_handler(on_pliant_assert);
  int32_t jaw_ids[SQUEEZE_JAW_PARTICLES];
  float jaw_targets[SQUEEZE_JAW_PARTICLES * 3U];
  squeeze_t closed = g_squeeze;
  closed.width_m = 0.0; /* any closure: only the ids are wanted */
  const uint32_t jaw_count = squeeze_jaw_contact(&closed, jaw_ids, jaw_targets);

  pliant_config_t config;
  require(pliant_config_init_default(&config));
  config.dim = 3U;
  config.particle_count = SQUEEZE_PARTICLES;
  config.rest_positions = g_squeeze.rest;
  config.drivable_ids = jaw_ids;
  config.drivable_count = jaw_count;
  config.tracker.min_residual_scale = 5e-5; /* the camera's noise, m */
  config.guard.max_strain = 0.08;           /* the block's limits */
  config.guard.max_force_n = 12.0;
  config.guard.squeeze_axis[0] = 1.0;
  config.guard.max_width_m = 0.1;
  config.guard.exceeded_stop_action = PLIANT_STOP_OPEN;
  /* One model form for the online estimate: the default's three msm_alpha rows triple the
   * estimator's candidate states, more than this 512 KB part leaves beside the rest. The form
   * (config.msm.msm_alpha, cluster radius) is the one `pliant estimate` chose offline. */
  config.estimator.alpha_candidates = 1;

  size_t need = 0U;
  require(pliant_workspace_size(&config, &need));
  if (need > sizeof g_workspace) {
    board_fail_safe(); /* raise WORKSPACE_BYTES to at least `need` */
  }
  require(pliant_init(g_workspace, sizeof g_workspace, &config, &g_pliant));
  require(pliant_get_deformation(g_pliant, &g_mailbox.deformation));
  require(pliant_get_estimate(g_pliant, &g_mailbox.estimate));
}

/* ---- control cycle (tick interrupt) ------------------------------------------------------ */

static pliant_verdict_t guard_cycle(double now_s, double wanted_width_m) {
  pliant_guard_input_t input;
  require(pliant_guard_input_init(&input));
  input.now_s = now_s;
  input.gripper.stamp_s = now_s;
  squeeze_gripper(&g_squeeze, &input.gripper.width_m, &input.gripper.force_n);
  input.gripper.valid = true;
  input.wrench.stamp_s = now_s;
  squeeze_wrench(&g_squeeze, input.wrench.wrench);
  input.wrench.valid = true;
  input.deformation.source = PLIANT_SOURCE_CALLER;
  input.deformation.stamp_s = g_mailbox.deformation.stamp_s;
  input.deformation.strain = g_mailbox.deformation.strain;
  input.deformation.valid = g_mailbox.deformation.valid;
  input.estimate.source = PLIANT_SOURCE_CALLER;
  input.estimate.stamp_s = g_mailbox.estimate.stamp_s;
  input.estimate.msm_beta = g_mailbox.estimate.msm_beta;
  input.estimate.msm_beta_std = g_mailbox.estimate.msm_beta_std;
  input.estimate.valid = g_mailbox.estimate.frames > 0U; /* an infinite sd is not a fault */

  pliant_verdict_t verdict;
  if (pliant_guard_update(g_pliant, &input, &verdict) != PLIANT_OK) {
    verdict.verdict = PLIANT_VERDICT_STOP; /* the bridge also wrote a STOP; be explicit */
    verdict.stop_action = PLIANT_STOP_FREEZE;
  }
  /* Closing makes the width smaller; opening further is always allowed. */
  double command = wanted_width_m;
  if (verdict.verdict == PLIANT_VERDICT_OK) {
    g_jaw.holding = false;
    if (!isnan(verdict.safe_width_m) && command < verdict.safe_width_m) {
      command = verdict.safe_width_m; /* never closer than the guard predicts safe */
    }
  } else {
    /* LIMIT or STOP: hold where the jaws are now (taken once, not re-read every cycle, so
     * sensor noise cannot walk the hold), or open to the contact width. */
    if (!g_jaw.holding) {
      if (isfinite(input.gripper.width_m)) {
        g_jaw.width_m = input.gripper.width_m; /* else: no reading, keep the last command */
      }
      g_jaw.holding = true;
    }
    double floor_m = g_jaw.width_m;
    if (verdict.verdict == PLIANT_VERDICT_STOP && verdict.stop_action == PLIANT_STOP_OPEN) {
      floor_m = isnan(verdict.contact_width_m) ? OPEN_WIDTH_M : verdict.contact_width_m;
    }
    if (command < floor_m) {
      command = floor_m;
    }
  }
  g_jaw.width_m = command;
  squeeze_command_width(&g_squeeze, command);
  return verdict;
}

static void control_tick(uint64_t tick) {
  static uint32_t phase_ticks;
  const double now_s = (double)tick * TICK_S;
  squeeze_advance(&g_squeeze, TICK_S);

  const phase_t phase = g_phase;
  const double wanted = phase == PHASE_GRASP ? WANTED_WIDTH_M : phase == PHASE_HOLD ? g_jaw.width_m : OPEN_WIDTH_M;
  const pliant_verdict_t verdict = guard_cycle(now_s, wanted);
  ++phase_ticks;
  if (phase == PHASE_GRASP && verdict.verdict != PLIANT_VERDICT_OK && verdict.in_contact) {
    g_phase = PHASE_HOLD;
    phase_ticks = 0U;
  } else if (phase == PHASE_HOLD && phase_ticks >= HOLD_TICKS) {
    g_phase = PHASE_RELEASE;
  } else if (phase == PHASE_RELEASE && g_squeeze.width_m >= OPEN_WIDTH_M) {
    g_phase = PHASE_RESET;
  }
}

/* ---- frame task (main loop) ------------------------------------------------------------- */

static void camera_frame(uint64_t tick, double dt_s) {
  static float positions[SQUEEZE_PARTICLES * 3U];
  int32_t jaw_ids[SQUEEZE_JAW_PARTICLES];
  float jaw_targets[SQUEEZE_JAW_PARTICLES * 3U];
  uint32_t lock = board_lock(); /* a consistent picture of the moving jaws */
  squeeze_camera(&g_squeeze, positions);
  const uint32_t jaw_count = squeeze_jaw_contact(&g_squeeze, jaw_ids, jaw_targets);
  board_unlock(lock);

  require(pliant_push_observations(g_pliant, (double)tick * TICK_S, positions, NULL));
  require(pliant_push_tool_contact(g_pliant, jaw_ids, jaw_targets, jaw_count));
  require(pliant_step_tracker(g_pliant, dt_s));
  require(pliant_update_estimate(g_pliant));
  mailbox_t results;
  require(pliant_get_deformation(g_pliant, &results.deformation));
  require(pliant_get_estimate(g_pliant, &results.estimate));

  lock = board_lock();
  g_mailbox = results;
  board_unlock(lock);
}

/* A new grasp: touches both groups, so the tick is kept out. */
static void new_grasp(void) {
  const uint32_t lock = board_lock();
  require(pliant_reset_grasp(g_pliant));
  require(pliant_get_deformation(g_pliant, &g_mailbox.deformation));
  require(pliant_get_estimate(g_pliant, &g_mailbox.estimate));
  g_phase = PHASE_GRASP;
  board_unlock(lock);
}

/* Queues the messages of `mask` for the UART. When the UART buffer lacks room, pliant drops
 * them whole and counts them (telemetry_not_sent). Reads both groups, so the tick is kept out. */
static void send_telemetry(uint64_t tick, uint32_t mask) {
  static uint8_t frames[TELEMETRY_BUFFER_BYTES];
  const size_t room = board_uart_room();
  size_t written = 0U;
  const uint32_t lock = board_lock();
  const pliant_status_t status = pliant_emit_telemetry(g_pliant, mask, tick * BOARD_TICK_US, frames,
                                                       room < sizeof frames ? room : sizeof frames, &written);
  board_unlock(lock);
  if (status != PLIANT_ERROR_MEMORY_TOO_SMALL) {
    require(status);
    (void)board_uart_queue(frames, written); /* fits: written <= room */
  }
}

int main(void) {
  squeeze_init(&g_squeeze, OPEN_WIDTH_M);
  setup(); /* slow (builds the guard's prediction table): before the control cycle starts */
  board_init(control_tick);

  uint64_t last_frame = board_ticks();
  uint64_t last_slow = last_frame;
  for (;;) {
    uint64_t tick = board_ticks();
    while (tick - last_frame < CAMERA_PERIOD_TICKS) {
      board_uart_poll();
      tick = board_ticks();
    }
    if (g_phase == PHASE_RESET) {
      new_grasp();
    }
    camera_frame(tick, (double)(tick - last_frame) * TICK_S);
    last_frame = tick;
    uint32_t mask = PLIANT_TELEMETRY_ESTIMATE | PLIANT_TELEMETRY_VERDICT;
    if (tick - last_slow >= SLOW_TELEMETRY_TICKS) {
      mask |= PLIANT_TELEMETRY_PARTICLES | PLIANT_TELEMETRY_COUNTERS;
      last_slow = tick;
    }
    send_telemetry(tick, mask);
  }
}
