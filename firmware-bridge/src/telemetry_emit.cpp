// pliant_emit_telemetry: the instance's results as telemetry frames (pliant_telemetry.h).
#include "bridge_internal.hpp"

using namespace pliant::bridge;

// pliant.h and the wire format number things the same way.
static_assert(PLIANT_TRACK_OBSERVED == PLIANT_TM_OBSERVED && PLIANT_TRACK_PREDICTED == PLIANT_TM_PREDICTED &&
              PLIANT_TRACK_LOST == PLIANT_TM_LOST);
static_assert(PLIANT_REASON_COUNT == PLIANT_TM_REASON_COUNT && PLIANT_GUARD_SOURCE_COUNT == PLIANT_TM_SOURCE_COUNT &&
              PLIANT_VERDICT_STOP + 1 == PLIANT_TM_VERDICT_COUNT &&
              PLIANT_STOP_OPEN + 1 == PLIANT_TM_STOP_ACTION_COUNT);
static_assert(PLIANT_COUNTER_TRACKER_FRAMES == PLIANT_TM_COUNTER_TRACKER_FRAMES &&
              PLIANT_COUNTER_TRACKER_FRAMES_REJECTED == PLIANT_TM_COUNTER_TRACKER_FRAMES_REJECTED &&
              PLIANT_COUNTER_OBSERVATIONS_USED == PLIANT_TM_COUNTER_OBSERVATIONS_USED &&
              PLIANT_COUNTER_OUTLIERS == PLIANT_TM_COUNTER_OBSERVATIONS_REJECTED &&
              PLIANT_COUNTER_PARTICLES_LOST == PLIANT_TM_COUNTER_PARTICLES_LOST &&
              PLIANT_COUNTER_ESTIMATOR_FRAMES == PLIANT_TM_COUNTER_ESTIMATOR_FRAMES &&
              PLIANT_COUNTER_ESTIMATOR_FRAMES_REJECTED == PLIANT_TM_COUNTER_ESTIMATOR_FRAMES_REJECTED &&
              PLIANT_COUNTER_GUARD_CYCLES == PLIANT_TM_COUNTER_GUARD_CYCLES &&
              PLIANT_COUNTER_GUARD_LIMIT_CYCLES == PLIANT_TM_COUNTER_GUARD_LIMIT_CYCLES &&
              PLIANT_COUNTER_GUARD_STOP_CYCLES == PLIANT_TM_COUNTER_GUARD_STOP_CYCLES &&
              PLIANT_COUNTER_GUARD_SLIP_CYCLES == PLIANT_TM_COUNTER_GUARD_SLIP_CYCLES &&
              PLIANT_COUNTER_GUARD_INPUTS_REFUSED == PLIANT_TM_COUNTER_GUARD_INPUTS_REFUSED &&
              PLIANT_COUNTER_GUARD_STALE_CYCLES == PLIANT_TM_COUNTER_GUARD_STALE_CYCLES &&
              PLIANT_COUNTER_TELEMETRY_NOT_SENT == PLIANT_TM_COUNTER_TELEMETRY_NOT_SENT &&
              PLIANT_COUNTER_CALLS_REJECTED == PLIANT_TM_COUNTER_BRIDGE_CALLS_REJECTED);

namespace {

constexpr std::uint32_t kMaxTelemetryParticles = 0xffffu;  // the particles message's u16 total

// Particles per packet for the instance's dimension (76 in 3D, 110 in 2D).
std::uint16_t chunk_particles(const pliant_t& instance) noexcept {
  return pliant_tm_particles_per_chunk(static_cast<std::uint8_t>(instance.dim), PLIANT_TM_MAX_FRAME);
}

struct Plan {
  std::size_t bytes = 0;
  std::uint32_t packets = 0;
};

constexpr std::size_t frame_bytes(std::size_t payload) noexcept {
  return PLIANT_TM_FRAME_SIZE(PLIANT_TM_HEADER_SIZE + payload + PLIANT_TM_CRC_SIZE);
}

// What the mask asks for now: worst-case bytes and packets.
pliant_status_t plan(const pliant_t& instance, std::uint32_t mask, Plan& out) noexcept {
  if ((mask & ~static_cast<std::uint32_t>(PLIANT_TELEMETRY_ALL)) != 0) return PLIANT_ERROR_INVALID_ARGUMENT;
  const Common& c = instance.common;
  Plan p;
  if ((mask & PLIANT_TELEMETRY_ESTIMATE) != 0 && c.estimator_enabled) {
    p.bytes += frame_bytes(PLIANT_TM_ESTIMATE_PAYLOAD);
    ++p.packets;
  }
  if ((mask & PLIANT_TELEMETRY_VERDICT) != 0 && c.has_verdict) {
    p.bytes += frame_bytes(PLIANT_TM_VERDICT_PAYLOAD);
    ++p.packets;
  }
  if ((mask & PLIANT_TELEMETRY_PARTICLES) != 0) {
    if (c.particle_count > kMaxTelemetryParticles) return PLIANT_ERROR_INVALID_ARGUMENT;
    const std::uint32_t per_chunk = chunk_particles(instance);
    if (per_chunk == 0) return PLIANT_ERROR_INTERNAL;
    for (std::uint32_t first = 0; first < c.particle_count; first += per_chunk) {
      const std::uint32_t count = std::min(per_chunk, c.particle_count - first);
      p.bytes += frame_bytes(PLIANT_TM_PARTICLES_HEAD + count * PLIANT_TM_PARTICLE_SIZE(instance.dim));
      ++p.packets;
    }
  }
  if ((mask & PLIANT_TELEMETRY_COUNTERS) != 0) {
    p.bytes += frame_bytes(PLIANT_TM_COUNTERS_HEAD + PLIANT_COUNTER_ID_COUNT * PLIANT_TM_COUNTER_SIZE);
    ++p.packets;
  }
  out = p;
  return PLIANT_OK;
}

// Appends one encoded frame; false if the encoder refused (a bug: the plan reserved the room).
bool append(std::int32_t encoded, std::size_t& used) noexcept {
  if (encoded <= 0) return false;
  used += static_cast<std::size_t>(encoded);
  return true;
}

float to_wire(double value) noexcept { return static_cast<float>(value); }

}  // namespace

extern "C" {

pliant_status_t pliant_telemetry_bytes(pliant_t* instance, uint32_t message_mask, size_t* out_bytes) {
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  constexpr std::uint8_t kCall = PLIANT_CALL_TELEMETRY_BYTES;
  if (out_bytes == nullptr) return reject(instance, kCall, PLIANT_ERROR_NULL_ARGUMENT);
  Plan p;
  const pliant_status_t planned = plan(*instance, message_mask, p);
  if (planned != PLIANT_OK) return reject(instance, kCall, planned);
  *out_bytes = p.bytes;
  return PLIANT_OK;
}

pliant_status_t pliant_emit_telemetry(pliant_t* instance, uint32_t message_mask, uint64_t stamp_us, uint8_t* buffer,
                                      size_t capacity, size_t* written) {
  if (written != nullptr) *written = 0;
  const pliant_status_t usable = check_instance(instance);
  if (usable != PLIANT_OK) return usable;
  constexpr std::uint8_t kCall = PLIANT_CALL_EMIT_TELEMETRY;
  if (buffer == nullptr || written == nullptr) return reject(instance, kCall, PLIANT_ERROR_NULL_ARGUMENT);
  Common& c = instance->common;
  Plan p;
  const pliant_status_t planned = plan(*instance, message_mask, p);
  if (planned != PLIANT_OK) return reject(instance, kCall, planned);
  if (capacity < p.bytes) {
    c.telemetry_not_sent += p.packets;
    return reject(instance, kCall, PLIANT_ERROR_MEMORY_TOO_SMALL);
  }
  // Encode into a copy of the sequence state: on an encoder refusal nothing is committed.
  pliant_tm_encoder_t encoder = c.telemetry;
  std::size_t used = 0;
  bool ok = true;

  if ((message_mask & PLIANT_TELEMETRY_ESTIMATE) != 0 && c.estimator_enabled) {
    pliant_tm_estimate_t e{};
    e.msm_beta = c.estimate.msm_beta;
    e.msm_beta_std = c.estimate.msm_beta_std;
    e.rms = c.estimate.rms;
    e.frames = c.estimate.frames;
    e.flags = static_cast<std::uint8_t>(
        (c.estimate.unique_minimum ? PLIANT_TM_ESTIMATE_UNIQUE_MINIMUM : 0u) |
        (c.estimate.frames > 0 && is_finite(c.estimate.msm_beta_std) ? PLIANT_TM_ESTIMATE_VALID : 0u));
    ok = ok && append(pliant_tm_encode_estimate(&encoder, stamp_us, &e, buffer + used, capacity - used), used);
  }

  if (ok && (message_mask & PLIANT_TELEMETRY_VERDICT) != 0 && c.has_verdict) {
    const pliant_verdict_t& v = c.last_verdict;
    pliant_tm_verdict_t w{};
    w.verdict = v.verdict;
    w.reason = v.reason;
    w.stop_action = v.stop_action;
    w.fault_sources = v.fault_sources;
    w.reasons = v.reasons;
    w.flags = static_cast<std::uint8_t>((v.in_contact ? PLIANT_TM_VERDICT_IN_CONTACT : 0u) |
                                        (v.slip ? PLIANT_TM_VERDICT_SLIP : 0u));
    w.closure_m = to_wire(v.closure_m);
    w.force_n = to_wire(v.force_n);
    w.strain = to_wire(v.strain);
    w.allowed_force_n = to_wire(v.allowed_force_n);
    w.predicted_strain = to_wire(v.predicted_strain);
    w.safe_closure_m = to_wire(v.safe_closure_m);
    w.safe_width_m = to_wire(v.safe_width_m);
    w.predicted_force_n = to_wire(v.predicted_force_n);
    w.beta_low = to_wire(v.beta_low);
    w.beta_high = to_wire(v.beta_high);
    ok = append(pliant_tm_encode_verdict(&encoder, stamp_us, &w, buffer + used, capacity - used), used);
  }

  if (ok && (message_mask & PLIANT_TELEMETRY_PARTICLES) != 0) {
    pliant_tm_particle_frame_t frame{};
    dispatch(instance, [&](auto& engine) {
      constexpr int kDim = std::decay_t<decltype(engine)>::Vec::RowsAtCompileTime;
      const int n = to_int(c.particle_count);
      for (int i = 0; i < n; ++i) {
        for (int d = 0; d < kDim; ++d) {
          engine.telemetry_positions[i * kDim + d] = static_cast<float>(engine.tracker.state.position[i](d));
        }
        engine.telemetry_status[i] = static_cast<std::uint8_t>(engine.tracker.status[i]);
      }
      frame.frame = engine.tracker.frame_index;
      frame.positions = engine.telemetry_positions;
      frame.status = engine.telemetry_status;
    });
    frame.dim = static_cast<std::uint8_t>(instance->dim);
    frame.total = static_cast<std::uint16_t>(c.particle_count);
    const std::uint32_t per_chunk = chunk_particles(*instance);
    for (std::uint32_t first = 0; ok && first < c.particle_count; first += per_chunk) {
      const auto count = static_cast<std::uint16_t>(std::min(per_chunk, c.particle_count - first));
      ok = append(pliant_tm_encode_particles(&encoder, stamp_us, &frame, static_cast<std::uint16_t>(first), count,
                                             buffer + used, capacity - used),
                  used);
    }
  }

  if (ok && (message_mask & PLIANT_TELEMETRY_COUNTERS) != 0) {
    pliant_counters_t counters{};
    (void)pliant_get_counters(instance, &counters);
    pliant_tm_counter_t entries[PLIANT_COUNTER_ID_COUNT];
    for (std::uint16_t id = 1; id <= PLIANT_COUNTER_ID_COUNT; ++id) {
      entries[id - 1].id = id;
      (void)pliant_counter_by_id(&counters, id, &entries[id - 1].value);
    }
    ok = append(
        pliant_tm_encode_counters(&encoder, stamp_us, entries, PLIANT_COUNTER_ID_COUNT, buffer + used, capacity - used),
        used);
  }

  if (!ok) {
    c.telemetry_not_sent += p.packets;
    return reject(instance, kCall, PLIANT_ERROR_INTERNAL);
  }
  c.telemetry = encoder;
  *written = used;
  return PLIANT_OK;
}

}  // extern "C"
