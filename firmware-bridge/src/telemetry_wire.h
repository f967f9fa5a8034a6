/* Private to the telemetry codec: little-endian field access and a COBS writer that encodes
 * while the packet is being produced, so an encoder needs no packet-sized scratch buffer. */
#ifndef PLIANT_TELEMETRY_WIRE_H
#define PLIANT_TELEMETRY_WIRE_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "pliant_telemetry.h"

static inline uint16_t pliant_tm_get_u16(const uint8_t* p) {
  return (uint16_t)((uint16_t)p[0] | (uint16_t)((uint16_t)p[1] << 8));
}

static inline uint32_t pliant_tm_get_u32(const uint8_t* p) {
  return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

static inline uint64_t pliant_tm_get_u64(const uint8_t* p) {
  return (uint64_t)pliant_tm_get_u32(p) | ((uint64_t)pliant_tm_get_u32(p + 4) << 32);
}

/* The IEEE bytes travel unchanged: memcpy between the real and an unsigned integer of its width
 * keeps NaN payloads and the sign of zero. */
static inline float pliant_tm_get_f32(const uint8_t* p) {
  const uint32_t bits = pliant_tm_get_u32(p);
  float value;
  memcpy(&value, &bits, sizeof value);
  return value;
}

static inline double pliant_tm_get_f64(const uint8_t* p) {
  const uint64_t bits = pliant_tm_get_u64(p);
  double value;
  memcpy(&value, &bits, sizeof value);
  return value;
}

/* Streaming COBS encoder into out[0 .. capacity), with the packet's running CRC. A block is
 * closed lazily when a 255th byte arrives, so a packet ending on a full block gets no extra
 * code byte (the COBS paper's encoding). Bytes past capacity are not written; `overflow` is set. */
typedef struct {
  uint8_t* out;
  size_t capacity;
  size_t pos;     /* next write position */
  size_t code_at; /* position of the current block's code byte */
  uint8_t code;   /* 1 + data bytes in the current block */
  uint8_t overflow;
  uint16_t crc; /* CRC-16/CCITT-FALSE of the packet bytes so far */
} pliant_tm_cobs_writer_t;

void pliant_tm_writer_begin(pliant_tm_cobs_writer_t* w, uint8_t* out, size_t capacity);
/* One packet byte: COBS-encoded, and added to the CRC when with_crc is nonzero. */
void pliant_tm_writer_byte(pliant_tm_cobs_writer_t* w, uint8_t byte, int with_crc);
void pliant_tm_writer_u16(pliant_tm_cobs_writer_t* w, uint16_t value);
void pliant_tm_writer_u32(pliant_tm_cobs_writer_t* w, uint32_t value);
void pliant_tm_writer_u64(pliant_tm_cobs_writer_t* w, uint64_t value);
void pliant_tm_writer_f32(pliant_tm_cobs_writer_t* w, float value);
void pliant_tm_writer_f64(pliant_tm_cobs_writer_t* w, double value);
/* Version, type, seq and stamp. */
void pliant_tm_writer_header(pliant_tm_cobs_writer_t* w, uint8_t type, uint16_t seq, uint64_t stamp_us);
/* Appends the CRC trailer (not itself CRC'd), closes the last block and writes the delimiter.
 * Returns the frame length, or PLIANT_TM_E_NO_ROOM. */
int32_t pliant_tm_writer_end(pliant_tm_cobs_writer_t* w);

/* CRC-16/CCITT-FALSE step: crc updated with one byte. */
uint16_t pliant_tm_crc16_update(uint16_t crc, uint8_t byte);

/* What became of one decoded packet (telemetry_packet.c). */
typedef enum {
  PLIANT_TM_PACKET_OK = 0,
  PLIANT_TM_PACKET_OVERSIZE,
  PLIANT_TM_PACKET_SHORT,
  PLIANT_TM_PACKET_CRC,
  PLIANT_TM_PACKET_VERSION,
  PLIANT_TM_PACKET_UNKNOWN_TYPE, /* header valid */
  PLIANT_TM_PACKET_BAD_LENGTH,   /* header valid */
  PLIANT_TM_PACKET_OUT_OF_RANGE  /* header valid */
} pliant_tm_packet_result_t;

/* Checks one packet (COBS already removed) and fills *out. out->header is set whenever the CRC
 * and version are good (for OK, UNKNOWN_TYPE, BAD_LENGTH, OUT_OF_RANGE); pointers in out->body
 * point into packet. */
pliant_tm_packet_result_t pliant_tm_parse_packet(const uint8_t* packet, size_t size, pliant_tm_message_t* out);

#endif /* PLIANT_TELEMETRY_WIRE_H */
