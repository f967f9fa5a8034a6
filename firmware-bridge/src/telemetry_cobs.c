/* Consistent Overhead Byte Stuffing (Cheshire and Baker): a streaming encoder and an in-place
 * capable decoder. */
#include <stdint.h>

#include "pliant_telemetry.h"
#include "telemetry_wire.h"

static void put(pliant_tm_cobs_writer_t* w, size_t at, uint8_t byte) {
  if (at < w->capacity) {
    w->out[at] = byte;
  } else {
    w->overflow = 1u;
  }
}

void pliant_tm_writer_begin(pliant_tm_cobs_writer_t* w, uint8_t* out, size_t capacity) {
  w->out = out;
  w->capacity = out != NULL ? capacity : 0u;
  w->code_at = 0u;
  w->pos = 1u;
  w->code = 1u;
  w->overflow = w->capacity == 0u ? 1u : 0u;
  w->crc = 0xFFFFu;
}

void pliant_tm_writer_byte(pliant_tm_cobs_writer_t* w, uint8_t byte, int with_crc) {
  if (with_crc) w->crc = pliant_tm_crc16_update(w->crc, byte);
  if (w->code == 0xFFu) { /* 254 data bytes: the block is full, start the next one */
    put(w, w->code_at, w->code);
    w->code_at = w->pos++;
    w->code = 1u;
  }
  if (byte == 0u) {
    put(w, w->code_at, w->code);
    w->code_at = w->pos++;
    w->code = 1u;
  } else {
    put(w, w->pos++, byte);
    ++w->code;
  }
}

/* Closes the last block; returns the encoded length or PLIANT_TM_E_NO_ROOM. */
static int32_t close_block(pliant_tm_cobs_writer_t* w) {
  put(w, w->code_at, w->code);
  if (w->overflow || w->pos > (size_t)INT32_MAX) return PLIANT_TM_E_NO_ROOM;
  return (int32_t)w->pos;
}

int32_t pliant_tm_writer_end(pliant_tm_cobs_writer_t* w) {
  const uint16_t crc = w->crc;
  pliant_tm_writer_byte(w, (uint8_t)(crc & 0xFFu), 0);
  pliant_tm_writer_byte(w, (uint8_t)(crc >> 8), 0);
  put(w, w->code_at, w->code);
  put(w, w->pos++, 0u); /* delimiter */
  if (w->overflow || w->pos > (size_t)INT32_MAX) return PLIANT_TM_E_NO_ROOM;
  return (int32_t)w->pos;
}

int32_t pliant_tm_cobs_encode(const uint8_t* in, size_t size, uint8_t* out, size_t capacity) {
  if ((in == NULL && size > 0u) || out == NULL || size > (size_t)(INT32_MAX / 2)) return PLIANT_TM_E_ARGUMENT;
  pliant_tm_cobs_writer_t w;
  pliant_tm_writer_begin(&w, out, capacity);
  for (size_t i = 0; i < size; ++i) pliant_tm_writer_byte(&w, in[i], 0);
  return close_block(&w);
}

int32_t pliant_tm_cobs_decode(const uint8_t* in, size_t size, uint8_t* out, size_t capacity) {
  if (in == NULL || out == NULL || size == 0u || size > (size_t)INT32_MAX) return PLIANT_TM_E_ARGUMENT;
  size_t r = 0;
  size_t w = 0;
  while (r < size) {
    const uint8_t code = in[r++];
    if (code == 0u) return PLIANT_TM_E_ARGUMENT;
    const size_t run = (size_t)code - 1u;
    if (run > size - r) return PLIANT_TM_E_ARGUMENT;
    /* w < r here, so moving forward within one buffer is safe for out == in. */
    for (size_t k = 0; k < run; ++k) {
      const uint8_t byte = in[r + k];
      if (byte == 0u) return PLIANT_TM_E_ARGUMENT;
      if (w >= capacity) return PLIANT_TM_E_NO_ROOM;
      out[w++] = byte;
    }
    r += run;
    /* Every block but a full one and the last stands for a zero byte. */
    if (code != 0xFFu && r < size) {
      if (w >= capacity) return PLIANT_TM_E_NO_ROOM;
      out[w++] = 0u;
    }
  }
  return (int32_t)w;
}
