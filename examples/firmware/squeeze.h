/* A synthetic gripper squeezing a foam block: the example's stand-in for the camera, gripper
 * and wrist force/torque drivers, so the control loop runs without hardware.
 *
 * The block is 4 x 3 x 2 particles at 10 mm spacing (30 mm along the squeeze axis x), centred
 * on the origin of the object frame. Two parallel jaws close along x. Once they touch, the block
 * compresses uniformly: closure c gives strain c / 30 mm along x and a Poisson bulge (0.3) across,
 * and the grip force is a stiffening spring, 1.5 N/mm x c + 0.2 N/mm^3 x c^3. The camera sees
 * every particle with +-0.05 mm of noise; the wrist sees the held weight (2 N) with +-0.01 N.
 * Deterministic (fixed pseudo-random seed), no allocation, no I/O.
 */
#ifndef PLIANT_EXAMPLE_SQUEEZE_H
#define PLIANT_EXAMPLE_SQUEEZE_H

#include <stdint.h>

#define SQUEEZE_NX 4U
#define SQUEEZE_NY 3U
#define SQUEEZE_NZ 2U
#define SQUEEZE_PARTICLES (SQUEEZE_NX * SQUEEZE_NY * SQUEEZE_NZ)
#define SQUEEZE_SPACING_M 0.010
/** Rest extent along x: the jaw opening at first contact, m. */
#define SQUEEZE_EXTENT_M (SQUEEZE_SPACING_M * (double)(SQUEEZE_NX - 1U))
/** Particles touching the jaws: both x faces. */
#define SQUEEZE_JAW_PARTICLES (2U * SQUEEZE_NY * SQUEEZE_NZ)
/** Fastest jaw motion, m/s. */
#define SQUEEZE_JAW_SPEED_M_PER_S 0.002

typedef struct squeeze_s {
  float rest[SQUEEZE_PARTICLES * 3U]; /**< rest positions, m, particle-major */
  double width_m;                     /**< jaw opening now */
  double target_width_m;              /**< commanded opening */
  uint32_t noise_state;               /**< xorshift32 state */
} squeeze_t;

/** Rest shape, jaws open at `width_m`, no motion commanded. */
void squeeze_init(squeeze_t* squeeze, double width_m);

/** Commands the jaw opening; the jaws move toward it at SQUEEZE_JAW_SPEED_M_PER_S. */
void squeeze_command_width(squeeze_t* squeeze, double width_m);

/** Advances the jaws by dt_s seconds. */
void squeeze_advance(squeeze_t* squeeze, double dt_s);

/** Jaw travel past first contact, m (0 while open). */
double squeeze_closure_m(const squeeze_t* squeeze);

/** What the camera sees: [SQUEEZE_PARTICLES * 3] positions, m, object frame. */
void squeeze_camera(squeeze_t* squeeze, float* positions);

/** The tool contact while the jaws touch the block: the particles on the x = min face (jaw A)
 *  and the x = max face (jaw B), ids into `ids` ([SQUEEZE_JAW_PARTICLES]) and where the jaws
 *  hold them into `targets` ([count * 3], m). Returns the count: 0 while the jaws are open,
 *  else SQUEEZE_JAW_PARTICLES. */
uint32_t squeeze_jaw_contact(const squeeze_t* squeeze, int32_t* ids, float* targets);

/** What the gripper reports: measured opening (m) and grip force (N). */
void squeeze_gripper(squeeze_t* squeeze, double* width_m, double* force_n);

/** What the wrist force/torque sensor reports: Fx Fy Fz (N), Tx Ty Tz (N m). */
void squeeze_wrench(squeeze_t* squeeze, double wrench[6]);

#endif /* PLIANT_EXAMPLE_SQUEEZE_H */
