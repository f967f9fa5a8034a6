/* Reading decoded particles and counters out of their wire bytes; counter names. */
#include "pliant_telemetry.h"
#include "telemetry_wire.h"

void pliant_tm_particles_get(const pliant_tm_particles_t* particles, uint16_t i, float position[3], uint8_t* status) {
  const uint8_t* item = particles->items + (size_t)i * PLIANT_TM_PARTICLE_SIZE((size_t)particles->dim);
  position[2] = 0.0f;
  for (unsigned axis = 0; axis < particles->dim; ++axis) position[axis] = pliant_tm_get_f32(item + 4u * axis);
  *status = item[4u * particles->dim];
}

pliant_tm_counter_t pliant_tm_counters_get(const pliant_tm_counters_t* counters, uint16_t i) {
  const uint8_t* item = counters->items + (size_t)i * PLIANT_TM_COUNTER_SIZE;
  pliant_tm_counter_t counter;
  counter.id = pliant_tm_get_u16(item);
  counter.value = pliant_tm_get_u32(item + 2);
  return counter;
}

const char* pliant_tm_counter_name(uint16_t id) {
  switch (id) {
    case PLIANT_TM_COUNTER_TRACKER_FRAMES: return "tracker_frames";
    case PLIANT_TM_COUNTER_TRACKER_FRAMES_REJECTED: return "tracker_frames_rejected";
    case PLIANT_TM_COUNTER_OBSERVATIONS_USED: return "observations_used";
    case PLIANT_TM_COUNTER_OBSERVATIONS_REJECTED: return "observations_rejected";
    case PLIANT_TM_COUNTER_PARTICLES_LOST: return "particles_lost";
    case PLIANT_TM_COUNTER_ESTIMATOR_FRAMES: return "estimator_frames";
    case PLIANT_TM_COUNTER_ESTIMATOR_FRAMES_REJECTED: return "estimator_frames_rejected";
    case PLIANT_TM_COUNTER_GUARD_CYCLES: return "guard_cycles";
    case PLIANT_TM_COUNTER_GUARD_LIMIT_CYCLES: return "guard_limit_cycles";
    case PLIANT_TM_COUNTER_GUARD_STOP_CYCLES: return "guard_stop_cycles";
    case PLIANT_TM_COUNTER_GUARD_SLIP_CYCLES: return "guard_slip_cycles";
    case PLIANT_TM_COUNTER_GUARD_INPUTS_REFUSED: return "guard_inputs_refused";
    case PLIANT_TM_COUNTER_GUARD_STALE_CYCLES: return "guard_stale_cycles";
    case PLIANT_TM_COUNTER_TELEMETRY_NOT_SENT: return "telemetry_not_sent";
    case PLIANT_TM_COUNTER_BRIDGE_CALLS_REJECTED: return "bridge_calls_rejected";
    default: return NULL;
  }
}
