/* The synthetic squeeze (see squeeze.h for the model). */
#include "squeeze.h"

#include <stddef.h>

#define POISSON_RATIO 0.3
#define STIFFNESS_N_PER_M 1500.0  /* 1.5 N/mm */
#define STIFFENING_N_PER_M3 2.0e8 /* 0.2 N/mm^3 */
#define CAMERA_NOISE_M 5e-5
#define GRIPPER_NOISE_M 1e-5
#define FORCE_NOISE_N 0.01
#define HELD_WEIGHT_N 2.0

/* Uniform in [-amplitude, amplitude] (xorshift32: deterministic, no state outside *state). */
static double noise(uint32_t* state, double amplitude) {
  uint32_t x = *state;
  x ^= x << 13;
  x ^= x >> 17;
  x ^= x << 5;
  *state = x;
  return amplitude * ((double)x / 2147483647.5 - 1.0);
}

void squeeze_init(squeeze_t* squeeze, double width_m) {
  const double half_y = 0.5 * SQUEEZE_SPACING_M * (double)(SQUEEZE_NY - 1U);
  const double half_z = 0.5 * SQUEEZE_SPACING_M * (double)(SQUEEZE_NZ - 1U);
  for (uint32_t k = 0; k < SQUEEZE_NZ; ++k) {
    for (uint32_t j = 0; j < SQUEEZE_NY; ++j) {
      for (uint32_t i = 0; i < SQUEEZE_NX; ++i) {
        float* p = &squeeze->rest[3U * ((k * SQUEEZE_NY + j) * SQUEEZE_NX + i)];
        p[0] = (float)(SQUEEZE_SPACING_M * (double)i - 0.5 * SQUEEZE_EXTENT_M);
        p[1] = (float)(SQUEEZE_SPACING_M * (double)j - half_y);
        p[2] = (float)(SQUEEZE_SPACING_M * (double)k - half_z);
      }
    }
  }
  squeeze->width_m = width_m;
  squeeze->target_width_m = width_m;
  squeeze->noise_state = 0x2545F491U;
}

void squeeze_command_width(squeeze_t* squeeze, double width_m) { squeeze->target_width_m = width_m; }

void squeeze_advance(squeeze_t* squeeze, double dt_s) {
  const double step = SQUEEZE_JAW_SPEED_M_PER_S * dt_s;
  const double error = squeeze->target_width_m - squeeze->width_m;
  if (error > step) {
    squeeze->width_m += step;
  } else if (error < -step) {
    squeeze->width_m -= step;
  } else {
    squeeze->width_m = squeeze->target_width_m;
  }
}

double squeeze_closure_m(const squeeze_t* squeeze) {
  const double closure = SQUEEZE_EXTENT_M - squeeze->width_m;
  return closure > 0.0 ? closure : 0.0;
}

/* Position of particle `id` under the current uniform compression. */
static void deformed(const squeeze_t* squeeze, uint32_t id, float* out) {
  const double strain = squeeze_closure_m(squeeze) / SQUEEZE_EXTENT_M;
  const float* p = &squeeze->rest[3U * id];
  out[0] = (float)((double)p[0] * (1.0 - strain));
  out[1] = (float)((double)p[1] * (1.0 + POISSON_RATIO * strain));
  out[2] = (float)((double)p[2] * (1.0 + POISSON_RATIO * strain));
}

void squeeze_camera(squeeze_t* squeeze, float* positions) {
  for (uint32_t id = 0; id < SQUEEZE_PARTICLES; ++id) {
    float* p = &positions[3U * id];
    deformed(squeeze, id, p);
    for (uint32_t axis = 0; axis < 3U; ++axis) {
      p[axis] = (float)((double)p[axis] + noise(&squeeze->noise_state, CAMERA_NOISE_M));
    }
  }
}

uint32_t squeeze_jaw_contact(const squeeze_t* squeeze, int32_t* ids, float* targets) {
  if (squeeze_closure_m(squeeze) <= 0.0) {
    return 0U;
  }
  uint32_t count = 0U;
  for (uint32_t k = 0; k < SQUEEZE_NZ; ++k) {
    for (uint32_t j = 0; j < SQUEEZE_NY; ++j) {
      const uint32_t row = (k * SQUEEZE_NY + j) * SQUEEZE_NX;
      const uint32_t face[2] = {row, row + SQUEEZE_NX - 1U};
      for (uint32_t side = 0; side < 2U; ++side) {
        ids[count] = (int32_t)face[side];
        deformed(squeeze, face[side], &targets[3U * count]);
        ++count;
      }
    }
  }
  return count;
}

void squeeze_gripper(squeeze_t* squeeze, double* width_m, double* force_n) {
  const double c = squeeze_closure_m(squeeze);
  const double force = c > 0.0 ? STIFFNESS_N_PER_M * c + STIFFENING_N_PER_M3 * c * c * c : 0.0;
  *width_m = squeeze->width_m + noise(&squeeze->noise_state, GRIPPER_NOISE_M);
  *force_n = force + noise(&squeeze->noise_state, FORCE_NOISE_N);
}

void squeeze_wrench(squeeze_t* squeeze, double wrench[6]) {
  for (size_t axis = 0; axis < 6U; ++axis) {
    wrench[axis] = noise(&squeeze->noise_state, FORCE_NOISE_N);
  }
  wrench[2] -= HELD_WEIGHT_N;
}
