/* One packet, COBS removed: CRC, version, type, then the payload's length and ranges. */
#include "pliant_telemetry.h"
#include "telemetry_wire.h"

static pliant_tm_packet_result_t parse_estimate(const uint8_t* p, size_t n, pliant_tm_estimate_t* e) {
  if (n != PLIANT_TM_ESTIMATE_PAYLOAD) return PLIANT_TM_PACKET_BAD_LENGTH;
  e->msm_beta = pliant_tm_get_f64(p);
  e->msm_beta_std = pliant_tm_get_f64(p + 8);
  e->rms = pliant_tm_get_f64(p + 16);
  e->frames = pliant_tm_get_u32(p + 24);
  e->flags = p[28];
  return PLIANT_TM_PACKET_OK;
}

static pliant_tm_packet_result_t parse_verdict(const uint8_t* p, size_t n, pliant_tm_verdict_t* v) {
  if (n != PLIANT_TM_VERDICT_PAYLOAD) return PLIANT_TM_PACKET_BAD_LENGTH;
  v->verdict = p[0];
  v->reason = p[1];
  v->stop_action = p[2];
  v->fault_sources = p[3];
  v->reasons = pliant_tm_get_u32(p + 4);
  v->flags = p[8];
  /* p[9..11] reserved: ignored, so that a later minor revision may use them. */
  float* const reals[10] = {&v->closure_m,        &v->force_n,        &v->strain,       &v->allowed_force_n,
                            &v->predicted_strain, &v->safe_closure_m, &v->safe_width_m, &v->predicted_force_n,
                            &v->beta_low,         &v->beta_high};
  for (size_t i = 0; i < 10u; ++i) *reals[i] = pliant_tm_get_f32(p + 12u + 4u * i);
  if (v->verdict >= PLIANT_TM_VERDICT_COUNT || v->reason >= PLIANT_TM_REASON_COUNT ||
      v->stop_action >= PLIANT_TM_STOP_ACTION_COUNT || (v->fault_sources >> PLIANT_TM_SOURCE_COUNT) != 0u ||
      (v->reasons >> PLIANT_TM_REASON_COUNT) != 0u) {
    return PLIANT_TM_PACKET_OUT_OF_RANGE;
  }
  return PLIANT_TM_PACKET_OK;
}

static pliant_tm_packet_result_t parse_particles(const uint8_t* p, size_t n, pliant_tm_particles_t* c) {
  if (n < PLIANT_TM_PARTICLES_HEAD) return PLIANT_TM_PACKET_BAD_LENGTH;
  c->frame = pliant_tm_get_u32(p);
  c->dim = p[4];
  /* p[5] reserved: ignored. */
  c->total = pliant_tm_get_u16(p + 6);
  c->first = pliant_tm_get_u16(p + 8);
  c->count = pliant_tm_get_u16(p + 10);
  c->items = p + PLIANT_TM_PARTICLES_HEAD;
  if (c->dim != 2u && c->dim != 3u) return PLIANT_TM_PACKET_OUT_OF_RANGE;
  const size_t each = PLIANT_TM_PARTICLE_SIZE((size_t)c->dim);
  if (n != PLIANT_TM_PARTICLES_HEAD + (size_t)c->count * each) return PLIANT_TM_PACKET_BAD_LENGTH;
  if ((uint32_t)c->first + c->count > c->total) return PLIANT_TM_PACKET_OUT_OF_RANGE;
  for (size_t i = 0; i < c->count; ++i) {
    if (c->items[i * each + each - 1u] > PLIANT_TM_LOST) return PLIANT_TM_PACKET_OUT_OF_RANGE;
  }
  return PLIANT_TM_PACKET_OK;
}

static pliant_tm_packet_result_t parse_counters(const uint8_t* p, size_t n, pliant_tm_counters_t* c) {
  if (n < PLIANT_TM_COUNTERS_HEAD) return PLIANT_TM_PACKET_BAD_LENGTH;
  c->count = pliant_tm_get_u16(p);
  c->items = p + PLIANT_TM_COUNTERS_HEAD;
  if (n != PLIANT_TM_COUNTERS_HEAD + (size_t)c->count * PLIANT_TM_COUNTER_SIZE) return PLIANT_TM_PACKET_BAD_LENGTH;
  /* count <= 168 here (the packet is at most 1024 bytes): the pairwise check stays bounded. */
  for (size_t i = 0; i < c->count; ++i) {
    const uint16_t id = pliant_tm_get_u16(c->items + i * PLIANT_TM_COUNTER_SIZE);
    for (size_t j = 0; j < i; ++j) {
      if (pliant_tm_get_u16(c->items + j * PLIANT_TM_COUNTER_SIZE) == id) return PLIANT_TM_PACKET_OUT_OF_RANGE;
    }
  }
  return PLIANT_TM_PACKET_OK;
}

pliant_tm_packet_result_t pliant_tm_parse_packet(const uint8_t* packet, size_t size, pliant_tm_message_t* out) {
  if (size > PLIANT_TM_MAX_PACKET) return PLIANT_TM_PACKET_OVERSIZE;
  if (size < PLIANT_TM_HEADER_SIZE + PLIANT_TM_CRC_SIZE) return PLIANT_TM_PACKET_SHORT;
  const size_t body = size - PLIANT_TM_CRC_SIZE;
  if (pliant_tm_crc16(packet, body) != pliant_tm_get_u16(packet + body)) return PLIANT_TM_PACKET_CRC;
  /* Version after the CRC: a corrupted first byte is a CRC mismatch, and a later version that
   * keeps the CRC trailer is reported as a version mismatch. */
  if (packet[0] != PLIANT_TM_VERSION) return PLIANT_TM_PACKET_VERSION;
  out->header.version = packet[0];
  out->header.type = packet[1];
  out->header.seq = pliant_tm_get_u16(packet + 2);
  out->header.stamp_us = pliant_tm_get_u64(packet + 4);
  const uint8_t* payload = packet + PLIANT_TM_HEADER_SIZE;
  const size_t n = body - PLIANT_TM_HEADER_SIZE;
  switch (out->header.type) {
    case PLIANT_TM_TYPE_ESTIMATE: return parse_estimate(payload, n, &out->body.estimate);
    case PLIANT_TM_TYPE_VERDICT: return parse_verdict(payload, n, &out->body.verdict);
    case PLIANT_TM_TYPE_PARTICLES: return parse_particles(payload, n, &out->body.particles);
    case PLIANT_TM_TYPE_COUNTERS: return parse_counters(payload, n, &out->body.counters);
    default: return PLIANT_TM_PACKET_UNKNOWN_TYPE;
  }
}
