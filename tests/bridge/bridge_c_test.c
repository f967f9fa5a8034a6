/* The firmware's view of pliant.h, in C99: a 4 x 4 x 3 particle block (1 cm spacing) squeezed
 * along x between two jaws, watched by a noisy 30 Hz camera, guarded at 1 kHz. The gripper
 * keeps closing whatever the guard says, so the verdict must go OK -> LIMIT -> STOP, with
 * LIMIT before the true strain reaches the object's limit. Also: the version, deliberate bad
 * calls (refused and counted), the estimate and the counters. Prints every failed check and
 * exits non-zero if any failed. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "pliant.h"

#define NX 4
#define NY 4
#define NZ 3
#define N (NX * NY * NZ)
#define SPACING 0.01
#define MAX_STRAIN 0.1
#define POISSON 0.3
#define STIFFNESS_N_PER_M 2000.0
#define NOISE_M 0.00005
#define CAMERA_PERIOD_S (1.0 / 30.0)
#define CYCLE_S 0.001
#define CLOSING_M_PER_S 0.003

static int g_failures = 0;

#define CHECK(condition)                                            \
  do {                                                              \
    if (!(condition)) {                                             \
      ++g_failures;                                                 \
      printf("FAILED %s:%d: %s\n", __FILE__, __LINE__, #condition); \
    }                                                               \
  } while (0)

#define CHECK_STATUS(call, expected)                                                                             \
  do {                                                                                                           \
    const pliant_status_t got_ = (call);                                                                         \
    if (got_ != (expected)) {                                                                                    \
      ++g_failures;                                                                                              \
      printf("FAILED %s:%d: %s returned %s, expected %s\n", __FILE__, __LINE__, #call, pliant_status_name(got_), \
             pliant_status_name(expected));                                                                      \
    }                                                                                                            \
  } while (0)

/* Deterministic noise: a 32-bit LCG, approximately normal (sum of four uniforms). */
static uint32_t g_seed = 12345U;
static double uniform(void) {
  g_seed = g_seed * 1664525U + 1013904223U;
  return (double)(g_seed >> 8U) / 16777216.0;
}
static double normal(void) { return (uniform() + uniform() + uniform() + uniform() - 2.0) * 1.7320508; }

static uint8_t g_block[4u * 1024u * 1024u];
static float g_rest[N * 3];
static float g_truth[N * 3];
static float g_observed[N * 3];
static int32_t g_jaw_a[NY * NZ];
static int32_t g_jaw_b[NY * NZ];
static int32_t g_drivable[2 * NY * NZ];

static int id_of(int x, int y, int z) { return (z * NY + y) * NX + x; }

/* Uniform compression by `strain` along x about the block's centre, Poisson bulge across. */
static void deform(double strain) {
  const double centre[3] = {0.5 * SPACING * (NX - 1), 0.5 * SPACING * (NY - 1), 0.5 * SPACING * (NZ - 1)};
  int i;
  int d;
  for (i = 0; i < N; ++i) {
    for (d = 0; d < 3; ++d) {
      const double scale = d == 0 ? 1.0 - strain : 1.0 + POISSON * strain;
      const double rest = (double)g_rest[i * 3 + d];
      g_truth[i * 3 + d] = (float)(centre[d] + (rest - centre[d]) * scale);
    }
  }
}

static void build_object(void) {
  int x, y, z, k = 0;
  for (z = 0; z < NZ; ++z) {
    for (y = 0; y < NY; ++y) {
      for (x = 0; x < NX; ++x) {
        const int i = id_of(x, y, z);
        g_rest[i * 3 + 0] = (float)(SPACING * x);
        g_rest[i * 3 + 1] = (float)(SPACING * y);
        g_rest[i * 3 + 2] = (float)(SPACING * z);
      }
    }
  }
  for (z = 0; z < NZ; ++z) {
    for (y = 0; y < NY; ++y) {
      g_jaw_a[k] = id_of(0, y, z);
      g_jaw_b[k] = id_of(NX - 1, y, z);
      g_drivable[2 * k] = g_jaw_a[k];
      g_drivable[2 * k + 1] = g_jaw_b[k];
      ++k;
    }
  }
}

static void check_version(void) {
  const char* text = pliant_version_string();
  char expected[32];
  CHECK(pliant_version() == PLIANT_VERSION_NUMBER);
  CHECK(pliant_abi_version() == PLIANT_ABI_VERSION);
  CHECK(text != NULL);
  sprintf(expected, "%d.%d.%d", PLIANT_VERSION_MAJOR, PLIANT_VERSION_MINOR, PLIANT_VERSION_PATCH);
  CHECK(text != NULL && strcmp(text, expected) == 0);
  CHECK(strcmp(pliant_status_name(PLIANT_OK), "ok") == 0);
  CHECK(strcmp(pliant_status_name((pliant_status_t)200), "unknown") == 0);
  CHECK(strcmp(pliant_verdict_name(PLIANT_VERDICT_STOP), "stop") == 0);
  CHECK(strcmp(pliant_reason_name(PLIANT_REASON_STRAIN_LIMIT), "strain_limit") == 0);
  CHECK(strcmp(pliant_source_name(PLIANT_SOURCE_CAMERA), "camera") == 0);
}

static void configure(pliant_config_t* cfg) {
  CHECK_STATUS(pliant_config_init_default(cfg), PLIANT_OK);
  cfg->dim = 3;
  cfg->particle_count = N;
  cfg->rest_positions = g_rest;
  cfg->drivable_ids = g_drivable;
  cfg->drivable_count = 2 * NY * NZ;
  cfg->tracker.min_residual_scale = NOISE_M;
  cfg->guard.max_strain = MAX_STRAIN;
  cfg->guard.max_force_n = 20.0;
  cfg->guard.squeeze_axis[0] = 1.0;
  cfg->guard.jaw_a_ids = g_jaw_a;
  cfg->guard.jaw_a_count = NY * NZ;
  cfg->guard.jaw_b_ids = g_jaw_b;
  cfg->guard.jaw_b_count = NY * NZ;
  cfg->guard.prediction_beta_points = 6;
  cfg->guard.prediction_closure_points = 16;
}

int main(void) {
  pliant_config_t cfg;
  pliant_t* pliant = NULL;
  size_t need = 0;
  const double extent = SPACING * (NX - 1);
  const double start_width = extent + 0.002;
  double now = 0.0;
  double next_frame = 0.0;
  double truth_strain = 0.0;
  double truth_strain_at_limit = -1.0;
  double closure_at_stop = -1.0;
  uint32_t frames = 0;
  uint32_t cycles = 0;
  uint32_t rejected_on_purpose = 0;
  int seen_ok = 0;
  int seen_limit = 0;
  int seen_stop = 0;
  int order_ok = 1;
  pliant_verdict_t verdict;
  uint8_t last_verdict = PLIANT_VERDICT_OK;
  int k;

  check_version();
  build_object();
  configure(&cfg);

  /* Sizes and init, with the refusals a firmware may meet. */
  CHECK_STATUS(pliant_workspace_size(&cfg, &need), PLIANT_OK);
  CHECK(need > 0 && need <= sizeof g_block);
  printf("workspace for %d particles in 3D: %lu bytes\n", N, (unsigned long)need);
  CHECK_STATUS(pliant_init(g_block, need - 1, &cfg, &pliant), PLIANT_ERROR_MEMORY_TOO_SMALL);
  CHECK(pliant == NULL);
  CHECK_STATUS(pliant_init(NULL, sizeof g_block, &cfg, &pliant), PLIANT_ERROR_NULL_ARGUMENT);
  CHECK_STATUS(pliant_step_tracker(pliant, CAMERA_PERIOD_S), PLIANT_ERROR_NULL_ARGUMENT);
  CHECK_STATUS(pliant_step_tracker((pliant_t*)(void*)g_block, CAMERA_PERIOD_S), PLIANT_ERROR_NOT_INITIALIZED);
  {
    pliant_config_t bad = cfg;
    bad.abi.config_size += 8U;
    CHECK_STATUS(pliant_workspace_size(&bad, &need), PLIANT_ERROR_ABI_MISMATCH);
    bad = cfg;
    bad.dim = 4;
    CHECK_STATUS(pliant_workspace_size(&bad, &need), PLIANT_ERROR_INVALID_ARGUMENT);
  }
  CHECK_STATUS(pliant_workspace_size(&cfg, &need), PLIANT_OK);
  CHECK_STATUS(pliant_init(g_block + 1, need, &cfg, &pliant), PLIANT_OK); /* any alignment */
  if (pliant == NULL) {
    printf("init failed; %d checks failed\n", g_failures);
    return 1;
  }
  {
    pliant_info_t info;
    CHECK_STATUS(pliant_get_info(pliant, &info), PLIANT_OK);
    CHECK(info.dim == 3 && info.particle_count == N && info.cluster_count == N);
    CHECK(info.guard_enabled && info.estimator_enabled);
    CHECK(fabs(info.guard_extent_m - extent) < 1e-6);
    CHECK(fabs(info.spacing_m - SPACING) < 1e-6);
  }

  /* Out-of-order and malformed calls: refused, counted. */
  CHECK_STATUS(pliant_step_tracker(pliant, CAMERA_PERIOD_S), PLIANT_ERROR_BAD_STATE);
  ++rejected_on_purpose;
  CHECK_STATUS(pliant_push_observations(pliant, NAN, g_rest, NULL), PLIANT_ERROR_NON_FINITE);
  ++rejected_on_purpose;
  CHECK_STATUS(pliant_guard_update(pliant, NULL, &verdict), PLIANT_ERROR_NULL_ARGUMENT);
  ++rejected_on_purpose;
  CHECK(verdict.verdict == PLIANT_VERDICT_STOP && verdict.reason == PLIANT_REASON_NOT_CONFIGURED);
  CHECK_STATUS(pliant_update_estimate(pliant), PLIANT_ERROR_BAD_STATE);
  ++rejected_on_purpose;

  /* The grasp: 1 kHz guard cycles, a camera frame every 1/30 s, closing at 3 mm/s. */
  for (k = 0; k < 4000 && !seen_stop; ++k) {
    pliant_guard_input_t in;
    const double width = start_width - CLOSING_M_PER_S * now;
    const double closure = extent - width > 0.0 ? extent - width : 0.0;
    truth_strain = closure / extent;
    if (now >= next_frame - 1e-9) {
      int i;
      int c = 0;
      int32_t ids[2 * NY * NZ];
      float targets[2 * NY * NZ * 3];
      deform(truth_strain);
      for (i = 0; i < N * 3; ++i) g_observed[i] = (float)((double)g_truth[i] + NOISE_M * normal());
      CHECK_STATUS(pliant_push_observations(pliant, now, g_observed, NULL), PLIANT_OK);
      if (closure > 0.0) {
        for (i = 0; i < 2 * NY * NZ; ++i) {
          ids[c] = g_drivable[i];
          memcpy(&targets[c * 3], &g_truth[g_drivable[i] * 3], 3 * sizeof(float));
          ++c;
        }
      }
      CHECK_STATUS(pliant_push_tool_contact(pliant, ids, targets, (uint32_t)c), PLIANT_OK);
      {
        const pliant_status_t stepped = pliant_step_tracker(pliant, CAMERA_PERIOD_S);
        CHECK(stepped == PLIANT_OK);
      }
      {
        const pliant_status_t estimated = pliant_update_estimate(pliant);
        CHECK(estimated == PLIANT_OK || estimated == PLIANT_NO_OBSERVATIONS);
      }
      ++frames;
      next_frame += CAMERA_PERIOD_S;
    }
    CHECK_STATUS(pliant_guard_input_init(&in), PLIANT_OK);
    in.now_s = now;
    in.gripper.stamp_s = now;
    in.gripper.width_m = width;
    in.gripper.force_n = STIFFNESS_N_PER_M * closure + 0.01 * normal();
    in.gripper.valid = true;
    in.wrench.stamp_s = now;
    in.wrench.wrench[0] = 0.02 * normal();
    in.wrench.wrench[1] = 0.02 * normal();
    in.wrench.wrench[2] = -1.0 + 0.02 * normal();
    in.wrench.wrench[3] = in.wrench.wrench[4] = in.wrench.wrench[5] = 0.0;
    in.wrench.valid = true;
    CHECK_STATUS(pliant_guard_update(pliant, &in, &verdict), PLIANT_OK);
    ++cycles;
    if (verdict.verdict == PLIANT_VERDICT_OK) {
      if (seen_limit || seen_stop) order_ok = 0;
      seen_ok = 1;
    } else if (verdict.verdict == PLIANT_VERDICT_LIMIT) {
      if (!seen_ok || seen_stop) order_ok = 0;
      if (!seen_limit) {
        truth_strain_at_limit = truth_strain;
        printf("LIMIT at t=%.3f s, closure %.2f mm, true strain %.4f, reason %s\n", now, closure * 1e3, truth_strain,
               pliant_reason_name(verdict.reason));
      }
      seen_limit = 1;
    } else {
      if (!seen_limit) order_ok = 0;
      seen_stop = 1;
      closure_at_stop = closure;
      printf("STOP at t=%.3f s, closure %.2f mm, true strain %.4f, reason %s, action %u\n", now, closure * 1e3,
             truth_strain, pliant_reason_name(verdict.reason), (unsigned)verdict.stop_action);
      CHECK(verdict.reason == PLIANT_REASON_STRAIN_EXCEEDED || verdict.reason == PLIANT_REASON_FORCE_EXCEEDED);
      CHECK(verdict.stop_action == PLIANT_STOP_OPEN);
      CHECK(verdict.in_contact);
    }
    if (verdict.verdict != last_verdict && verdict.verdict == PLIANT_VERDICT_OK && cycles > 1) {
      CHECK(verdict.fault_sources == 0);
    }
    last_verdict = verdict.verdict;
    now += CYCLE_S;
  }
  CHECK(seen_ok);
  CHECK(seen_limit);
  CHECK(seen_stop);
  CHECK(order_ok);
  CHECK(truth_strain_at_limit >= 0.0 && truth_strain_at_limit <= MAX_STRAIN);
  CHECK(closure_at_stop > 0.0 && closure_at_stop / extent <= MAX_STRAIN * 1.25);

  /* The tracked state and the estimate. */
  {
    float tracked[N * 3];
    uint8_t status[N];
    uint32_t frame_index = 0;
    int i;
    int observed = 0;
    CHECK_STATUS(pliant_get_tracked(pliant, tracked, status, N - 1, NULL), PLIANT_ERROR_INVALID_ARGUMENT);
    ++rejected_on_purpose;
    CHECK_STATUS(pliant_get_tracked(pliant, tracked, status, N, &frame_index), PLIANT_OK);
    CHECK(frame_index == frames);
    for (i = 0; i < N; ++i) {
      CHECK(status[i] <= PLIANT_TRACK_LOST);
      observed += status[i] == PLIANT_TRACK_OBSERVED;
      CHECK(isfinite(tracked[i * 3]) && fabsf(tracked[i * 3] - g_truth[i * 3]) < 0.002f);
    }
    CHECK(observed > N / 2);
  }
  {
    pliant_estimate_t estimate;
    pliant_deformation_t deformation;
    CHECK_STATUS(pliant_get_estimate(pliant, &estimate), PLIANT_OK);
    CHECK(estimate.frames == frames);
    CHECK(estimate.msm_beta >= 0.0 && estimate.msm_beta <= 1.0);
    CHECK(estimate.rms >= 0.0 && estimate.rms < 0.002);
    printf("estimate: msm_beta %.3f sd %.3f rms %.2e m over %u frames\n", estimate.msm_beta, estimate.msm_beta_std,
           estimate.rms, (unsigned)estimate.frames);
    CHECK_STATUS(pliant_get_deformation(pliant, &deformation), PLIANT_OK);
    CHECK(deformation.valid && deformation.clusters_measured == N);
    CHECK(fabs(deformation.strain - truth_strain) < 0.05);
  }

  /* Counters: what happened, by the telemetry's ids too. */
  {
    pliant_counters_t counters;
    uint32_t value = 0;
    uint16_t id;
    CHECK_STATUS(pliant_get_counters(pliant, &counters), PLIANT_OK);
    CHECK(counters.tracker_frames == frames);
    CHECK(counters.estimator_frames == frames);
    CHECK(counters.guard_cycles == cycles);
    CHECK(counters.guard_limit_cycles > 0 && counters.guard_stop_cycles > 0);
    CHECK(counters.calls_rejected == rejected_on_purpose);
    CHECK(counters.last_rejected_call == PLIANT_CALL_GET_TRACKED);
    CHECK(counters.last_rejected_status == PLIANT_ERROR_INVALID_ARGUMENT);
    CHECK(counters.observations_used > 0);
    CHECK(counters.estimator_frames_skipped == 0 && counters.frames_replaced == 0);
    for (id = 1; id <= PLIANT_COUNTER_ID_COUNT; ++id) {
      CHECK_STATUS(pliant_counter_by_id(&counters, id, &value), PLIANT_OK);
    }
    CHECK_STATUS(pliant_counter_by_id(&counters, PLIANT_COUNTER_GUARD_CYCLES, &value), PLIANT_OK);
    CHECK(value == cycles);
    CHECK_STATUS(pliant_counter_by_id(&counters, 0, &value), PLIANT_ERROR_INVALID_ARGUMENT);
    CHECK_STATUS(pliant_counter_by_id(&counters, PLIANT_COUNTER_ID_COUNT + 1, &value), PLIANT_ERROR_INVALID_ARGUMENT);
  }

  /* Telemetry: frames for everything, each ending in its 0x00 delimiter. */
  {
    static uint8_t telemetry[8192];
    size_t bytes = 0;
    size_t written = 0;
    size_t k_byte;
    size_t delimiters = 0;
    CHECK_STATUS(pliant_telemetry_bytes(pliant, PLIANT_TELEMETRY_ALL, &bytes), PLIANT_OK);
    CHECK(bytes > 0 && bytes <= sizeof telemetry);
    CHECK_STATUS(pliant_emit_telemetry(pliant, PLIANT_TELEMETRY_ALL, 1000000u, telemetry, sizeof telemetry, &written),
                 PLIANT_OK);
    CHECK(written > 0 && written <= bytes);
    for (k_byte = 0; k_byte < written; ++k_byte) delimiters += telemetry[k_byte] == 0;
    CHECK(written > 0 && telemetry[written - 1] == 0);
    CHECK(delimiters == 4); /* estimate, verdict, one particles chunk (48 < 76), counters */
  }

  /* A new grasp: back to rest, the guard forgets the contact. */
  CHECK_STATUS(pliant_reset_grasp(pliant), PLIANT_OK);
  {
    pliant_estimate_t estimate;
    CHECK_STATUS(pliant_get_estimate(pliant, &estimate), PLIANT_OK);
    CHECK(estimate.frames == 0 && !estimate.valid);
  }

  if (g_failures != 0) {
    printf("%d checks failed\n", g_failures);
    return 1;
  }
  printf("all checks passed (%u frames, %u guard cycles)\n", (unsigned)frames, (unsigned)cycles);
  return 0;
}
