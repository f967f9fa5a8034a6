/* Streaming decoder: collects bytes up to a 0x00 delimiter, removes COBS in place, checks the
 * packet and counts every frame it cannot deliver under exactly one reason. */
#include <string.h>

#include "pliant_telemetry.h"
#include "telemetry_wire.h"

void pliant_tm_decoder_init(pliant_tm_decoder_t* decoder) {
  if (decoder != NULL) memset(decoder, 0, sizeof *decoder);
}

static void track_sequence(pliant_tm_decoder_t* d, uint16_t seq, uint64_t stamp_us) {
  if (d->have_seq) {
    const uint16_t jump = (uint16_t)(seq - d->next_seq);
    /* An earlier stamp means the emitter restarted (or packets were reordered): its sequence
     * number says nothing about loss. Otherwise half the sequence space ahead counts as missed
     * packets, and anything else went back. */
    const int went_back = stamp_us < d->last_stamp_us || jump >= 0x8000u;
    if (went_back) {
      ++d->counters.seq_backward;
    } else if (jump != 0u) {
      d->counters.seq_missed += jump;
    }
  }
  d->next_seq = (uint16_t)(seq + 1u);
  d->last_stamp_us = stamp_us;
  d->have_seq = 1u;
}

/* One complete frame of `length` encoded bytes in d->frame: 1 when *out is a message. */
static int take_frame(pliant_tm_decoder_t* d, size_t length, pliant_tm_message_t* out) {
  ++d->counters.frames;
  const int32_t decoded = pliant_tm_cobs_decode(d->frame, length, d->frame, sizeof d->frame);
  if (decoded < 0) {
    ++d->counters.cobs_error;
    return 0;
  }
  pliant_tm_message_t message;
  const pliant_tm_packet_result_t result = pliant_tm_parse_packet(d->frame, (size_t)decoded, &message);
  switch (result) {
    case PLIANT_TM_PACKET_OVERSIZE: ++d->counters.oversize; return 0;
    case PLIANT_TM_PACKET_SHORT: ++d->counters.short_packet; return 0;
    case PLIANT_TM_PACKET_CRC: ++d->counters.crc_mismatch; return 0;
    case PLIANT_TM_PACKET_VERSION: ++d->counters.version; return 0;
    default: break;
  }
  /* The CRC vouches for the header even when the payload is unusable. */
  track_sequence(d, message.header.seq, message.header.stamp_us);
  switch (result) {
    case PLIANT_TM_PACKET_UNKNOWN_TYPE: ++d->counters.unknown_type; return 0;
    case PLIANT_TM_PACKET_BAD_LENGTH: ++d->counters.bad_length; return 0;
    case PLIANT_TM_PACKET_OUT_OF_RANGE: ++d->counters.out_of_range; return 0;
    default: break;
  }
  ++d->counters.messages;
  *out = message;
  return 1;
}

int pliant_tm_decoder_push(pliant_tm_decoder_t* decoder, const uint8_t* data, size_t size, size_t* consumed,
                           pliant_tm_message_t* out) {
  if (consumed != NULL) *consumed = 0u;
  if (decoder == NULL || consumed == NULL || out == NULL || (data == NULL && size > 0u)) return 0;
  for (size_t i = 0; i < size; ++i) {
    const uint8_t byte = data[i];
    if (byte != 0u) {
      if (decoder->discarding) continue;
      if (decoder->length >= PLIANT_TM_MAX_FRAME - 1u) {
        /* Longer than any valid frame: count it once, skip to the next delimiter. */
        ++decoder->counters.frames;
        ++decoder->counters.oversize;
        decoder->discarding = 1u;
        decoder->length = 0u;
        continue;
      }
      decoder->frame[decoder->length++] = byte;
      continue;
    }
    if (decoder->discarding) {
      decoder->discarding = 0u;
      continue;
    }
    const size_t length = decoder->length;
    decoder->length = 0u;
    if (length == 0u) continue; /* empty frame: idle fill or a start mark */
    if (take_frame(decoder, length, out)) {
      *consumed = i + 1u;
      return 1;
    }
  }
  *consumed = size;
  return 0;
}

void pliant_tm_decoder_finish(pliant_tm_decoder_t* decoder) {
  if (decoder == NULL) return;
  if (decoder->length > 0u && !decoder->discarding) {
    ++decoder->counters.frames;
    ++decoder->counters.truncated;
  }
  decoder->length = 0u;
  decoder->discarding = 0u;
  decoder->have_seq = 0u;
}
