/* pliant telemetry codec: wire format version 1 (docs/telemetry.md is the specification).
 *
 * The controller firmware encodes what pliant decides (estimate, guard verdict, tracked
 * particles, counters) into frames; a host decodes them from any byte pipe (UART, UDP, file).
 *
 * Frame on the wire: COBS(packet) followed by one 0x00 delimiter. Packet (little-endian):
 *   u8 version (1) | u8 type | u16 seq | u64 stamp_us | payload | u16 CRC-16/CCITT-FALSE
 * A packet is at most PLIANT_TM_MAX_PACKET (1024) bytes, a frame at most PLIANT_TM_MAX_FRAME
 * (1030) bytes including its delimiter.
 *
 * Contract of every function here:
 *   - C99, no heap, no global or static mutable state, no I/O, no locale; reentrant.
 *   - Real-time safe: bounded time, linear in the bytes handled (stated per function).
 *   - Reals travel as IEEE-754 bytes (memcpy), assembled little-endian byte by byte, so the
 *     codec gives the same bytes on any host byte order. NaN and infinities pass unchanged.
 *
 * Encoding (firmware side):
 *   pliant_tm_encoder_t enc;
 *   pliant_tm_encoder_init(&enc, 0);
 *   uint8_t frame[PLIANT_TM_MAX_FRAME];
 *   int32_t n = pliant_tm_encode_verdict(&enc, now_us, &verdict, frame, sizeof frame);
 *   if (n > 0) uart_write(frame, (size_t)n);  // else n is a negative PLIANT_TM_E_* code
 * Each successful encode takes the encoder's next sequence number; a failed one takes none.
 *
 * Decoding (host side, or a second controller): a poll API over any split of the byte stream.
 *   pliant_tm_decoder_t dec;           // about 1.1 KiB, caller-owned (static, stack or heap)
 *   pliant_tm_decoder_init(&dec);
 *   while (size > 0) {
 *     pliant_tm_message_t msg;
 *     size_t used = 0;
 *     if (pliant_tm_decoder_push(&dec, data, size, &used, &msg)) handle(&msg);
 *     data += used; size -= used;
 *   }
 *   pliant_tm_decoder_finish(&dec);   // at the end of the stream: counts a cut-off frame
 * push consumes bytes up to and including the delimiter that completes a usable message and
 * returns 1 with the message, or consumes everything and returns 0. Frames it cannot use are
 * dropped and counted in dec.counters (pliant_tm_decoder_counters_t), never reported as errors.
 */
#ifndef PLIANT_TELEMETRY_H
#define PLIANT_TELEMETRY_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- sizes ------------------------------------------------------------------------------ */

#define PLIANT_TM_VERSION 1u
#define PLIANT_TM_HEADER_SIZE 12u /* version, type, seq, stamp_us */
#define PLIANT_TM_CRC_SIZE 2u
#define PLIANT_TM_MAX_PACKET 1024u
#define PLIANT_TM_MAX_PAYLOAD (PLIANT_TM_MAX_PACKET - PLIANT_TM_HEADER_SIZE - PLIANT_TM_CRC_SIZE)
/* Frame bytes for a packet of n bytes (n >= 1): COBS adds one byte per started 254-byte block,
 * then the 0x00 delimiter. */
#define PLIANT_TM_FRAME_SIZE(n) ((n) + ((n) + 253u) / 254u + 1u)
#define PLIANT_TM_MAX_FRAME 1030u /* PLIANT_TM_FRAME_SIZE(PLIANT_TM_MAX_PACKET) */

#define PLIANT_TM_ESTIMATE_PAYLOAD 29u
#define PLIANT_TM_VERDICT_PAYLOAD 52u
#define PLIANT_TM_PARTICLES_HEAD 12u
#define PLIANT_TM_COUNTERS_HEAD 2u
#define PLIANT_TM_COUNTER_SIZE 6u
/* Wire bytes of one particle: dim x f32 position, u8 status. */
#define PLIANT_TM_PARTICLE_SIZE(dim) (4u * (dim) + 1u)
/* Most particles one packet holds: 110 in 2D, 76 in 3D. Most counters: 168. */
#define PLIANT_TM_MAX_CHUNK_PARTICLES(dim) \
  ((PLIANT_TM_MAX_PAYLOAD - PLIANT_TM_PARTICLES_HEAD) / PLIANT_TM_PARTICLE_SIZE(dim))
#define PLIANT_TM_MAX_COUNTERS ((PLIANT_TM_MAX_PAYLOAD - PLIANT_TM_COUNTERS_HEAD) / PLIANT_TM_COUNTER_SIZE)

/* ---- status codes (negative returns of the encoders) ------------------------------------ */

#define PLIANT_TM_E_ARGUMENT (-1)  /* NULL pointer, or a field out of its wire range (see each type) */
#define PLIANT_TM_E_NO_ROOM (-2)   /* the frame does not fit in the caller's buffer; nothing usable written */
#define PLIANT_TM_E_TOO_LARGE (-3) /* the packet would exceed PLIANT_TM_MAX_PACKET */

/* ---- message types ---------------------------------------------------------------------- */

#define PLIANT_TM_TYPE_ESTIMATE 1u
#define PLIANT_TM_TYPE_VERDICT 2u
#define PLIANT_TM_TYPE_PARTICLES 3u
#define PLIANT_TM_TYPE_COUNTERS 4u

/* Fixed part of every packet. */
typedef struct {
  uint8_t version;   /* PLIANT_TM_VERSION */
  uint8_t type;      /* PLIANT_TM_TYPE_* */
  uint16_t seq;      /* +1 per packet the emitter sends (any type), wraps */
  uint64_t stamp_us; /* the controller's monotonic clock, microseconds */
} pliant_tm_header_t;

/* 1: estimate. NaN means "not known". */
#define PLIANT_TM_ESTIMATE_UNIQUE_MINIMUM 0x01u
#define PLIANT_TM_ESTIMATE_VALID 0x02u
typedef struct {
  double msm_beta;     /* [0, 1] */
  double msm_beta_std; /* +inf until identifiable */
  double rms;          /* residual of the best candidate, the object's length unit */
  uint32_t frames;     /* frames used */
  uint8_t flags;       /* PLIANT_TM_ESTIMATE_* bits; other bits are sent and read as given */
} pliant_tm_estimate_t;

/* 2: verdict. Codes are the core's (pliant/core/grasp_guard.hpp): GraspVerdict, GuardReason,
 * StopAction, GuardSource. Reals in SI units (m, N), strain dimensionless; NaN: not known. */
#define PLIANT_TM_VERDICT_COUNT 3u     /* verdict < 3: 0 ok, 1 limit, 2 stop */
#define PLIANT_TM_REASON_COUNT 19u     /* reason < 19: 0 none ... 18 estimate_uncertain */
#define PLIANT_TM_STOP_ACTION_COUNT 2u /* 0 freeze, 1 open */
#define PLIANT_TM_SOURCE_COUNT 5u      /* fault_sources bits 0..4: gripper, wrench, camera, estimate, clock */
#define PLIANT_TM_VERDICT_IN_CONTACT 0x01u
#define PLIANT_TM_VERDICT_SLIP 0x02u
typedef struct {
  uint8_t verdict;
  uint8_t reason;
  uint8_t stop_action;
  uint8_t fault_sources; /* bit (1 << source); bits 5..7 must be zero */
  uint32_t reasons;      /* bit (1 << reason) per active reason; bits 19..31 must be zero */
  uint8_t flags;         /* PLIANT_TM_VERDICT_* bits; other bits are sent and read as given */
  float closure_m;
  float force_n;
  float strain;
  float allowed_force_n;
  float predicted_strain;
  float safe_closure_m;
  float safe_width_m;
  float predicted_force_n;
  float beta_low;
  float beta_high;
} pliant_tm_verdict_t;

/* 3: particles. Status of a particle in a frame: */
#define PLIANT_TM_OBSERVED 0u
#define PLIANT_TM_PREDICTED 1u /* occluded or rejected as an outlier: position follows the model */
#define PLIANT_TM_LOST 2u

/* One tracked frame, as the encoder reads it: every particle of the frame. */
typedef struct {
  uint32_t frame;         /* the tracker's frame index */
  uint8_t dim;            /* 2 or 3 */
  uint16_t total;         /* particles in the frame */
  const float* positions; /* total x dim, particle-major (x, y[, z] of particle 0, then 1...),
                             object frame, its length unit; read only, caller-owned */
  const uint8_t* status;  /* total entries, PLIANT_TM_OBSERVED / PREDICTED / LOST */
} pliant_tm_particle_frame_t;

/* One decoded particles chunk: particles first .. first + count - 1 of frame `frame`. The
 * particle data stays in wire form in the decoder's buffer: read it with
 * pliant_tm_particles_get. `items` is valid until the next call on that decoder. */
typedef struct {
  uint32_t frame;
  uint8_t dim; /* 2 or 3 */
  uint16_t total;
  uint16_t first;
  uint16_t count;       /* first + count <= total */
  const uint8_t* items; /* count x PLIANT_TM_PARTICLE_SIZE(dim) wire bytes */
} pliant_tm_particles_t;

/* 4: counters. Ids (docs/telemetry.md); a decoder shows unknown ids by number. */
#define PLIANT_TM_COUNTER_TRACKER_FRAMES 1u
#define PLIANT_TM_COUNTER_TRACKER_FRAMES_REJECTED 2u
#define PLIANT_TM_COUNTER_OBSERVATIONS_USED 3u
#define PLIANT_TM_COUNTER_OBSERVATIONS_REJECTED 4u
#define PLIANT_TM_COUNTER_PARTICLES_LOST 5u
#define PLIANT_TM_COUNTER_ESTIMATOR_FRAMES 6u
#define PLIANT_TM_COUNTER_ESTIMATOR_FRAMES_REJECTED 7u
#define PLIANT_TM_COUNTER_GUARD_CYCLES 8u
#define PLIANT_TM_COUNTER_GUARD_LIMIT_CYCLES 9u
#define PLIANT_TM_COUNTER_GUARD_STOP_CYCLES 10u
#define PLIANT_TM_COUNTER_GUARD_SLIP_CYCLES 11u
#define PLIANT_TM_COUNTER_GUARD_INPUTS_REFUSED 12u
#define PLIANT_TM_COUNTER_GUARD_STALE_CYCLES 13u
#define PLIANT_TM_COUNTER_TELEMETRY_NOT_SENT 14u
#define PLIANT_TM_COUNTER_BRIDGE_CALLS_REJECTED 15u

typedef struct {
  uint16_t id;
  uint32_t value; /* monotonic, wraps at 2^32 */
} pliant_tm_counter_t;

/* One decoded counters message; read entries with pliant_tm_counters_get. `items` (count x 6
 * wire bytes) is valid until the next call on that decoder. Ids are unique within a message. */
typedef struct {
  uint16_t count;
  const uint8_t* items;
} pliant_tm_counters_t;

/* A decoded message: header.type says which member of `body` is set. */
typedef struct {
  pliant_tm_header_t header;
  union {
    pliant_tm_estimate_t estimate;
    pliant_tm_verdict_t verdict;
    pliant_tm_particles_t particles;
    pliant_tm_counters_t counters;
  } body;
} pliant_tm_message_t;

/* ---- CRC and COBS ----------------------------------------------------------------------- */

/* CRC-16/CCITT-FALSE (poly 0x1021, init 0xFFFF, no reflection, no final XOR) of size bytes.
 * data may be NULL only when size is 0. O(size). */
uint16_t pliant_tm_crc16(const uint8_t* data, size_t size);

/* COBS-encodes size bytes of `in` into `out` (no delimiter appended). Returns the encoded length
 * (at most size + (size + 253) / 254, and 1 for size 0; no zero byte in it) or PLIANT_TM_E_NO_ROOM when capacity is too
 * small, PLIANT_TM_E_ARGUMENT on NULL pointers or size > INT32_MAX / 2. in and out must not
 * overlap. O(size). */
int32_t pliant_tm_cobs_encode(const uint8_t* in, size_t size, uint8_t* out, size_t capacity);

/* COBS-decodes size encoded bytes (without the delimiter; none of them may be zero) into `out`.
 * out may equal in (in-place decoding); other overlaps are not allowed. Returns the decoded
 * length (< size), PLIANT_TM_E_ARGUMENT on a zero byte, a code that runs past the end, NULL
 * pointers or size 0, PLIANT_TM_E_NO_ROOM when capacity is too small. O(size). */
int32_t pliant_tm_cobs_decode(const uint8_t* in, size_t size, uint8_t* out, size_t capacity);

/* ---- encoder ---------------------------------------------------------------------------- */

typedef struct {
  uint16_t next_seq; /* sequence number of the next packet encoded */
} pliant_tm_encoder_t;

void pliant_tm_encoder_init(pliant_tm_encoder_t* encoder, uint16_t first_seq);

/* Each pliant_tm_encode_* writes one complete frame (COBS packet and 0x00 delimiter) into
 * out[0 .. capacity) and returns its length (> 0), or a negative PLIANT_TM_E_* code, in which
 * case out holds nothing usable and the sequence number is not consumed. A buffer of
 * PLIANT_TM_MAX_FRAME bytes always suffices. O(frame length); no other memory touched. */

/* 1: estimate, 29-byte payload: frame of 45 bytes. */
int32_t pliant_tm_encode_estimate(pliant_tm_encoder_t* encoder, uint64_t stamp_us, const pliant_tm_estimate_t* estimate,
                                  uint8_t* out, size_t capacity);

/* 2: verdict, 52-byte payload: frame of 68 bytes. PLIANT_TM_E_ARGUMENT when verdict, reason,
 * stop_action, fault_sources or reasons is out of its range above. */
int32_t pliant_tm_encode_verdict(pliant_tm_encoder_t* encoder, uint64_t stamp_us, const pliant_tm_verdict_t* verdict,
                                 uint8_t* out, size_t capacity);

/* 3: particles first .. first + count - 1 of `frame` as one chunk. PLIANT_TM_E_ARGUMENT when dim
 * is not 2 or 3, first + count > total, a status is above PLIANT_TM_LOST, or a pointer is NULL
 * while total > 0; PLIANT_TM_E_TOO_LARGE when count > PLIANT_TM_MAX_CHUNK_PARTICLES(dim). */
int32_t pliant_tm_encode_particles(pliant_tm_encoder_t* encoder, uint64_t stamp_us,
                                   const pliant_tm_particle_frame_t* frame, uint16_t first, uint16_t count,
                                   uint8_t* out, size_t capacity);

/* Splitting a frame into chunks: the most particles of dimension dim (2 or 3) whose particles
 * frame fits in frame_capacity bytes and in one packet (0 when not even one fits, or dim is
 * invalid). Send chunks first = 0, n, 2n, ... with count = min(n, total - first); a frame of
 * total 0 is one chunk of count 0. O(1). */
uint16_t pliant_tm_particles_per_chunk(uint8_t dim, size_t frame_capacity);

/* The split done for the caller: encodes the chunk of `frame` that starts at particle *next
 * (0 for the first chunk) with as many particles as pliant_tm_particles_per_chunk allows for
 * capacity, and on success advances *next past them. The frame is sent when *next == total:
 *   uint16_t next = 0;
 *   do {
 *     int32_t n = pliant_tm_encode_particles_next(&enc, now_us, &frame, &next, buf, sizeof buf);
 *     if (n < 0) break;                     // count it as not sent
 *     uart_write(buf, (size_t)n);
 *   } while (next < frame.total);
 * PLIANT_TM_E_ARGUMENT when next is NULL or *next > total (and as pliant_tm_encode_particles),
 * PLIANT_TM_E_NO_ROOM when not even one particle fits. O(frame length). */
int32_t pliant_tm_encode_particles_next(pliant_tm_encoder_t* encoder, uint64_t stamp_us,
                                        const pliant_tm_particle_frame_t* frame, uint16_t* next, uint8_t* out,
                                        size_t capacity);

/* 4: counters, count entries (count <= PLIANT_TM_MAX_COUNTERS, else PLIANT_TM_E_TOO_LARGE).
 * PLIANT_TM_E_ARGUMENT when counters is NULL with count > 0, or two entries share an id.
 * O(count^2) for the duplicate check (count <= 168). */
int32_t pliant_tm_encode_counters(pliant_tm_encoder_t* encoder, uint64_t stamp_us, const pliant_tm_counter_t* counters,
                                  uint16_t count, uint8_t* out, size_t capacity);

/* ---- decoded payload access ------------------------------------------------------------- */

/* Particle i (< particles->count) of a decoded chunk: its id is particles->first + i; writes dim
 * coordinates to position (the third is set to 0 in 2D) and its status. O(1). */
void pliant_tm_particles_get(const pliant_tm_particles_t* particles, uint16_t i, float position[3], uint8_t* status);

/* Entry i (< counters->count) of a decoded counters message. O(1). */
pliant_tm_counter_t pliant_tm_counters_get(const pliant_tm_counters_t* counters, uint16_t i);

/* snake_case name of a counter id ("tracker_frames", ...), NULL for an id this version does
 * not know. */
const char* pliant_tm_counter_name(uint16_t id);

/* ---- streaming decoder ------------------------------------------------------------------ */

/* Monotonic counters (wrap at 2^32). Every non-empty frame the decoder sees ends up in exactly
 * one of `messages` or the drop reasons cobs_error .. unknown_type, truncated; so their sum is
 * `frames`. The sequence counters are about packets, not frames. */
typedef struct {
  uint32_t frames;       /* non-empty frames seen (a run of bytes ended by 0x00 or by finish) */
  uint32_t messages;     /* frames delivered as messages */
  uint32_t cobs_error;   /* a COBS code byte runs past the end of the frame */
  uint32_t crc_mismatch; /* the CRC-16 trailer does not match the packet */
  uint32_t oversize;     /* no delimiter within PLIANT_TM_MAX_FRAME bytes, or a packet over 1024 */
  uint32_t short_packet; /* fewer than header + CRC (14) bytes */
  uint32_t version;      /* CRC good, protocol version not PLIANT_TM_VERSION */
  uint32_t bad_length;   /* payload length does not match the type */
  uint32_t out_of_range; /* a field outside its range (dim, first + count, status, codes, ids) */
  uint32_t unknown_type; /* CRC good, version 1, type this decoder does not know: skipped */
  uint32_t truncated;    /* the stream ended inside a frame (counted by pliant_tm_decoder_finish) */
  uint32_t seq_missed;   /* packets missed: sum of the forward jumps of the sequence number
                            (less than half its range ahead, stamp_us not earlier) */
  uint32_t seq_backward; /* times the stream went back: the sequence number (more than half its
                            range ahead, or repeated) or stamp_us went back: packets reordered
                            or repeated, or the emitter restarted. Nothing counted as missed. */
} pliant_tm_decoder_counters_t;

/* Caller-owned decoder state; no pointers to outside memory. Copyable only between calls. */
typedef struct {
  uint8_t frame[PLIANT_TM_MAX_FRAME]; /* the encoded frame being received, decoded in place */
  size_t length;                      /* bytes of frame[] in use */
  uint8_t discarding;                 /* 1: oversize run, skipping to the next delimiter */
  uint8_t have_seq;                   /* 1: next_seq and last_stamp_us are known */
  uint16_t next_seq;                  /* the sequence number expected next */
  uint64_t last_stamp_us;             /* stamp of the last packet with a good CRC */
  pliant_tm_decoder_counters_t counters;
} pliant_tm_decoder_t;

/* Resets the decoder: empty buffer, no expected sequence number, counters zero. */
void pliant_tm_decoder_init(pliant_tm_decoder_t* decoder);

/* Feeds up to size bytes. Returns 1 when a message is complete: *out holds it and *consumed
 * (<= size) says how many bytes were used (the rest belongs to later frames: push them next).
 * Returns 0 when all size bytes were consumed without completing a message (out untouched).
 * Pointers inside *out (particles.items, counters.items) stay valid until the next push, finish
 * or init on this decoder. Empty frames (0x00 0x00) are ignored: emitters may send a lone 0x00 to
 * mark a frame start. Returns 0 with *consumed = 0 when decoder, consumed or out is NULL, or data
 * is NULL with size > 0. O(size + PLIANT_TM_MAX_FRAME) per call. */
int pliant_tm_decoder_push(pliant_tm_decoder_t* decoder, const uint8_t* data, size_t size, size_t* consumed,
                           pliant_tm_message_t* out);

/* End of stream: a frame still being received is dropped and counted as truncated; the decoder
 * is ready for a new stream (sequence tracking restarts, counters are kept). O(1). */
void pliant_tm_decoder_finish(pliant_tm_decoder_t* decoder);

#ifdef __cplusplus
}
#endif

#endif /* PLIANT_TELEMETRY_H */
