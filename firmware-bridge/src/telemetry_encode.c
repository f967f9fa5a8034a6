/* Message encoders: each builds its packet byte by byte straight into the COBS writer. */
#include <stdint.h>
#include <string.h>

#include "pliant_telemetry.h"
#include "telemetry_wire.h"

void pliant_tm_writer_u16(pliant_tm_cobs_writer_t* w, uint16_t value) {
  pliant_tm_writer_byte(w, (uint8_t)(value & 0xFFu), 1);
  pliant_tm_writer_byte(w, (uint8_t)(value >> 8), 1);
}

void pliant_tm_writer_u32(pliant_tm_cobs_writer_t* w, uint32_t value) {
  for (unsigned shift = 0; shift < 32u; shift += 8u) pliant_tm_writer_byte(w, (uint8_t)((value >> shift) & 0xFFu), 1);
}

void pliant_tm_writer_u64(pliant_tm_cobs_writer_t* w, uint64_t value) {
  for (unsigned shift = 0; shift < 64u; shift += 8u) pliant_tm_writer_byte(w, (uint8_t)((value >> shift) & 0xFFu), 1);
}

void pliant_tm_writer_f32(pliant_tm_cobs_writer_t* w, float value) {
  uint32_t bits;
  memcpy(&bits, &value, sizeof bits);
  pliant_tm_writer_u32(w, bits);
}

void pliant_tm_writer_f64(pliant_tm_cobs_writer_t* w, double value) {
  uint64_t bits;
  memcpy(&bits, &value, sizeof bits);
  pliant_tm_writer_u64(w, bits);
}

void pliant_tm_writer_header(pliant_tm_cobs_writer_t* w, uint8_t type, uint16_t seq, uint64_t stamp_us) {
  pliant_tm_writer_byte(w, (uint8_t)PLIANT_TM_VERSION, 1);
  pliant_tm_writer_byte(w, type, 1);
  pliant_tm_writer_u16(w, seq);
  pliant_tm_writer_u64(w, stamp_us);
}

void pliant_tm_encoder_init(pliant_tm_encoder_t* encoder, uint16_t first_seq) {
  if (encoder != NULL) encoder->next_seq = first_seq;
}

/* Ends the frame; the sequence number is consumed only by a frame that was written whole. */
static int32_t finish(pliant_tm_encoder_t* encoder, pliant_tm_cobs_writer_t* w) {
  const int32_t length = pliant_tm_writer_end(w);
  if (length > 0) encoder->next_seq = (uint16_t)(encoder->next_seq + 1u);
  return length;
}

int32_t pliant_tm_encode_estimate(pliant_tm_encoder_t* encoder, uint64_t stamp_us, const pliant_tm_estimate_t* estimate,
                                  uint8_t* out, size_t capacity) {
  if (encoder == NULL || estimate == NULL || out == NULL) return PLIANT_TM_E_ARGUMENT;
  pliant_tm_cobs_writer_t w;
  pliant_tm_writer_begin(&w, out, capacity);
  pliant_tm_writer_header(&w, (uint8_t)PLIANT_TM_TYPE_ESTIMATE, encoder->next_seq, stamp_us);
  pliant_tm_writer_f64(&w, estimate->msm_beta);
  pliant_tm_writer_f64(&w, estimate->msm_beta_std);
  pliant_tm_writer_f64(&w, estimate->rms);
  pliant_tm_writer_u32(&w, estimate->frames);
  pliant_tm_writer_byte(&w, estimate->flags, 1);
  return finish(encoder, &w);
}

int32_t pliant_tm_encode_verdict(pliant_tm_encoder_t* encoder, uint64_t stamp_us, const pliant_tm_verdict_t* v,
                                 uint8_t* out, size_t capacity) {
  if (encoder == NULL || v == NULL || out == NULL) return PLIANT_TM_E_ARGUMENT;
  if (v->verdict >= PLIANT_TM_VERDICT_COUNT || v->reason >= PLIANT_TM_REASON_COUNT ||
      v->stop_action >= PLIANT_TM_STOP_ACTION_COUNT || (v->fault_sources >> PLIANT_TM_SOURCE_COUNT) != 0u ||
      (v->reasons >> PLIANT_TM_REASON_COUNT) != 0u) {
    return PLIANT_TM_E_ARGUMENT;
  }
  pliant_tm_cobs_writer_t w;
  pliant_tm_writer_begin(&w, out, capacity);
  pliant_tm_writer_header(&w, (uint8_t)PLIANT_TM_TYPE_VERDICT, encoder->next_seq, stamp_us);
  pliant_tm_writer_byte(&w, v->verdict, 1);
  pliant_tm_writer_byte(&w, v->reason, 1);
  pliant_tm_writer_byte(&w, v->stop_action, 1);
  pliant_tm_writer_byte(&w, v->fault_sources, 1);
  pliant_tm_writer_u32(&w, v->reasons);
  pliant_tm_writer_byte(&w, v->flags, 1);
  for (int i = 0; i < 3; ++i) pliant_tm_writer_byte(&w, 0u, 1); /* reserved */
  const float reals[10] = {v->closure_m,        v->force_n,        v->strain,       v->allowed_force_n,
                           v->predicted_strain, v->safe_closure_m, v->safe_width_m, v->predicted_force_n,
                           v->beta_low,         v->beta_high};
  for (int i = 0; i < 10; ++i) pliant_tm_writer_f32(&w, reals[i]);
  return finish(encoder, &w);
}

int32_t pliant_tm_encode_particles(pliant_tm_encoder_t* encoder, uint64_t stamp_us,
                                   const pliant_tm_particle_frame_t* frame, uint16_t first, uint16_t count,
                                   uint8_t* out, size_t capacity) {
  if (encoder == NULL || frame == NULL || out == NULL) return PLIANT_TM_E_ARGUMENT;
  if (frame->dim != 2u && frame->dim != 3u) return PLIANT_TM_E_ARGUMENT;
  if ((uint32_t)first + count > frame->total) return PLIANT_TM_E_ARGUMENT;
  if (count > 0u && (frame->positions == NULL || frame->status == NULL)) return PLIANT_TM_E_ARGUMENT;
  if (count > PLIANT_TM_MAX_CHUNK_PARTICLES(frame->dim)) return PLIANT_TM_E_TOO_LARGE;
  for (uint32_t i = first; i < (uint32_t)first + count; ++i) {
    if (frame->status[i] > PLIANT_TM_LOST) return PLIANT_TM_E_ARGUMENT;
  }
  pliant_tm_cobs_writer_t w;
  pliant_tm_writer_begin(&w, out, capacity);
  pliant_tm_writer_header(&w, (uint8_t)PLIANT_TM_TYPE_PARTICLES, encoder->next_seq, stamp_us);
  pliant_tm_writer_u32(&w, frame->frame);
  pliant_tm_writer_byte(&w, frame->dim, 1);
  pliant_tm_writer_byte(&w, 0u, 1); /* reserved */
  pliant_tm_writer_u16(&w, frame->total);
  pliant_tm_writer_u16(&w, first);
  pliant_tm_writer_u16(&w, count);
  for (uint32_t i = first; i < (uint32_t)first + count && !w.overflow; ++i) {
    const float* position = frame->positions + (size_t)i * frame->dim;
    for (unsigned axis = 0; axis < frame->dim; ++axis) pliant_tm_writer_f32(&w, position[axis]);
    pliant_tm_writer_byte(&w, frame->status[i], 1);
  }
  return finish(encoder, &w);
}

uint16_t pliant_tm_particles_per_chunk(uint8_t dim, size_t frame_capacity) {
  if ((dim != 2u && dim != 3u) || frame_capacity < 2u) return 0u;
  const size_t fixed = PLIANT_TM_HEADER_SIZE + PLIANT_TM_PARTICLES_HEAD + PLIANT_TM_CRC_SIZE;
  const size_t each = PLIANT_TM_PARTICLE_SIZE((size_t)dim);
  /* Largest packet whose frame fits: p + ceil(p / 254) + 1 <= capacity. */
  const size_t encoded = frame_capacity - 1u;
  const size_t packet = encoded - (encoded + 254u) / 255u;
  if (packet < fixed) return 0u;
  size_t n = (packet - fixed) / each;
  if (n > PLIANT_TM_MAX_CHUNK_PARTICLES((size_t)dim)) n = PLIANT_TM_MAX_CHUNK_PARTICLES((size_t)dim);
  while (n > 0u && PLIANT_TM_FRAME_SIZE(fixed + n * each) > frame_capacity) --n;
  return (uint16_t)n;
}

int32_t pliant_tm_encode_particles_next(pliant_tm_encoder_t* encoder, uint64_t stamp_us,
                                        const pliant_tm_particle_frame_t* frame, uint16_t* next, uint8_t* out,
                                        size_t capacity) {
  if (frame == NULL || next == NULL || *next > frame->total) return PLIANT_TM_E_ARGUMENT;
  const uint16_t per_chunk = pliant_tm_particles_per_chunk(frame->dim, capacity);
  const uint16_t left = (uint16_t)(frame->total - *next);
  if (per_chunk == 0u) return (frame->dim == 2u || frame->dim == 3u) ? PLIANT_TM_E_NO_ROOM : PLIANT_TM_E_ARGUMENT;
  const uint16_t count = left < per_chunk ? left : per_chunk;
  const int32_t length = pliant_tm_encode_particles(encoder, stamp_us, frame, *next, count, out, capacity);
  if (length > 0) *next = (uint16_t)(*next + count);
  return length;
}

int32_t pliant_tm_encode_counters(pliant_tm_encoder_t* encoder, uint64_t stamp_us, const pliant_tm_counter_t* counters,
                                  uint16_t count, uint8_t* out, size_t capacity) {
  if (encoder == NULL || out == NULL || (counters == NULL && count > 0u)) return PLIANT_TM_E_ARGUMENT;
  if (count > PLIANT_TM_MAX_COUNTERS) return PLIANT_TM_E_TOO_LARGE;
  for (uint16_t i = 0; i < count; ++i) {
    for (uint16_t j = 0; j < i; ++j) {
      if (counters[i].id == counters[j].id) return PLIANT_TM_E_ARGUMENT;
    }
  }
  pliant_tm_cobs_writer_t w;
  pliant_tm_writer_begin(&w, out, capacity);
  pliant_tm_writer_header(&w, (uint8_t)PLIANT_TM_TYPE_COUNTERS, encoder->next_seq, stamp_us);
  pliant_tm_writer_u16(&w, count);
  for (uint16_t i = 0; i < count && !w.overflow; ++i) {
    pliant_tm_writer_u16(&w, counters[i].id);
    pliant_tm_writer_u32(&w, counters[i].value);
  }
  return finish(encoder, &w);
}
