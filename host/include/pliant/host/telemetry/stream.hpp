// Reading a telemetry stream: bytes from a ByteSource through the codec's streaming decoder
// (pliant_telemetry.h) to a callback, bounded by a message count, a duration, the end of input
// or a stop request. Host code: allocates; exceptions thrown by the callback propagate.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <string>

#include "pliant/host/telemetry/byte_source.hpp"
#include "pliant_telemetry.h"

namespace pliant::host::telemetry {

struct StreamLimits {
  std::uint64_t max_messages = 0;  ///< stop after this many decoded messages; 0: no limit
  double max_duration_s = std::numeric_limits<double>::infinity();  ///< wall clock, > 0
};

/// Why reading stopped.
enum class StreamEnd {
  end_of_input,  ///< end of file
  count,         ///< max_messages decoded
  duration,      ///< max_duration_s elapsed
  stopped,       ///< should_stop() returned true (the command line: SIGINT or SIGTERM)
  hangup,        ///< the device went away
  read_error,    ///< the source threw; StreamResult::error says why
};

/// "end of input", "count reached", "duration reached", "stopped", "device hung up", "read error".
const char* stream_end_text(StreamEnd end);

/// Decoded messages by type.
struct MessageCounts {
  std::uint64_t estimate = 0;
  std::uint64_t verdict = 0;
  std::uint64_t particles = 0;
  std::uint64_t counters = 0;
  std::uint64_t total() const { return estimate + verdict + particles + counters; }
};

struct StreamResult {
  StreamEnd end = StreamEnd::end_of_input;
  std::string error;  ///< the read error's message when end == read_error
  MessageCounts messages;
  pliant_tm_decoder_counters_t decoder{};  ///< after pliant_tm_decoder_finish
  std::uint64_t bytes = 0;                 ///< bytes read from the source
  double elapsed_s = 0;                    ///< wall clock spent reading
  /// Drops by reason summed (cobs_error .. unknown_type, truncated).
  std::uint64_t dropped() const;
};

/// Reads `source` until a limit is met, the input ends, the device hangs up, a read fails or
/// `should_stop` (optional; polled at least every 100 ms) returns true. Each decoded message is
/// passed to `on_message`; its particle and counter payload pointers are valid during that call
/// only. Stops right after the max_messages-th message. At the end the decoder is finished, so
/// a frame cut off by the end of the stream, a hangup, the duration or a stop request counts as
/// truncated. A read error does not throw: it ends the stream with end == read_error, so that
/// the caller can still save what was decoded.
StreamResult read_telemetry(ByteSource& source, const StreamLimits& limits,
                            const std::function<void(const pliant_tm_message_t&)>& on_message,
                            const std::function<bool()>& should_stop = {});

/// One line for the end of a run: messages by type, drops by reason, sequence gaps, bytes,
/// time and why it ended, e.g.
/// "messages 12 (estimate 1, verdict 5, particles 4, counters 2); dropped 1 (cobs_error 0,
///  crc_mismatch 1, ...); sequence: 3 missed, 0 backward; 1830 bytes in 0.42 s; end of input"
std::string stream_summary(const StreamResult& result);

}  // namespace pliant::host::telemetry
