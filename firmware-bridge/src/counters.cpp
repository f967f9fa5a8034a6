// Counters: the core components' and the bridge's own, in the telemetry's terms.
#include "bridge_internal.hpp"

using namespace pliant::bridge;

extern "C" {

pliant_status_t pliant_get_counters(pliant_t* instance, pliant_counters_t* out) {
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  if (out == nullptr) return reject(instance, PLIANT_CALL_GET_COUNTERS, PLIANT_ERROR_NULL_ARGUMENT);
  const Common& c = instance->common;
  pliant_counters_t k{};
  dispatch(instance, [&](auto& engine) {
    const pliant::TrackerCounters& t = engine.tracker.counters;
    k.tracker_frames = t.frames;
    k.tracker_frames_rejected = t.rejected_frames;
    k.observations_used = t.observations;
    k.outliers = t.outliers;
    k.particles_lost = t.lost_events;
    k.tracker_unobserved = t.unobserved;
    k.tracker_empty_frames = t.empty_frames;
    if (c.estimator_enabled) {
      k.estimator_frames_rejected = engine.estimator.rejected_frames;
      k.estimator_empty_frames = engine.estimator.empty_frames;
    }
    if (c.guard_enabled) {
      const pliant::GraspGuardCounters& g = engine.guard.counters;
      k.guard_cycles = g.cycles;
      k.guard_limit_cycles = g.limit_cycles;
      k.guard_stop_cycles = g.stop_cycles;
      k.guard_slip_cycles = g.slip_cycles;
      for (int s = 0; s < pliant::kGuardSourceCount; ++s) {
        k.guard_refused[s] = g.refused[s];
        k.guard_stale[s] = g.stale_cycles[s];
        k.guard_inputs_refused += g.refused[s];  // wraps like every counter
        k.guard_stale_cycles += g.stale_cycles[s];
      }
    }
  });
  k.estimator_frames = c.estimator_frames;
  k.telemetry_not_sent = c.telemetry_not_sent;
  k.calls_rejected = c.calls_rejected;
  k.estimator_frames_skipped = c.estimator_frames_skipped;
  k.frames_replaced = c.frames_replaced;
  k.strain_unmeasured = c.strain_unmeasured;
  k.last_rejected_status = c.last_rejected_status;
  k.last_rejected_call = c.last_rejected_call;
  *out = k;
  return PLIANT_OK;
}

pliant_status_t pliant_counter_by_id(const pliant_counters_t* counters, uint16_t id, uint32_t* out_value) {
  if (counters == nullptr || out_value == nullptr) return PLIANT_ERROR_NULL_ARGUMENT;
  const pliant_counters_t& k = *counters;
  switch (id) {
    case PLIANT_COUNTER_TRACKER_FRAMES: *out_value = k.tracker_frames; break;
    case PLIANT_COUNTER_TRACKER_FRAMES_REJECTED: *out_value = k.tracker_frames_rejected; break;
    case PLIANT_COUNTER_OBSERVATIONS_USED: *out_value = k.observations_used; break;
    case PLIANT_COUNTER_OUTLIERS: *out_value = k.outliers; break;
    case PLIANT_COUNTER_PARTICLES_LOST: *out_value = k.particles_lost; break;
    case PLIANT_COUNTER_ESTIMATOR_FRAMES: *out_value = k.estimator_frames; break;
    case PLIANT_COUNTER_ESTIMATOR_FRAMES_REJECTED: *out_value = k.estimator_frames_rejected; break;
    case PLIANT_COUNTER_GUARD_CYCLES: *out_value = k.guard_cycles; break;
    case PLIANT_COUNTER_GUARD_LIMIT_CYCLES: *out_value = k.guard_limit_cycles; break;
    case PLIANT_COUNTER_GUARD_STOP_CYCLES: *out_value = k.guard_stop_cycles; break;
    case PLIANT_COUNTER_GUARD_SLIP_CYCLES: *out_value = k.guard_slip_cycles; break;
    case PLIANT_COUNTER_GUARD_INPUTS_REFUSED: *out_value = k.guard_inputs_refused; break;
    case PLIANT_COUNTER_GUARD_STALE_CYCLES: *out_value = k.guard_stale_cycles; break;
    case PLIANT_COUNTER_TELEMETRY_NOT_SENT: *out_value = k.telemetry_not_sent; break;
    case PLIANT_COUNTER_CALLS_REJECTED: *out_value = k.calls_rejected; break;
    default: return PLIANT_ERROR_INVALID_ARGUMENT;
  }
  return PLIANT_OK;
}

}  // extern "C"
