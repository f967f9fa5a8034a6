// The read loop: source -> decoder -> callback, with the bounds checked between reads.
#include "pliant/host/telemetry/stream.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <vector>

namespace pliant::host::telemetry {
namespace {

constexpr int kPollMs = 100;
// A UDP datagram is at most 64 KiB: reading whole datagrams never truncates one.
constexpr std::size_t kReadBytes = 64 * 1024;

void count(MessageCounts& counts, std::uint8_t type) {
  switch (type) {
    case PLIANT_TM_TYPE_ESTIMATE: ++counts.estimate; break;
    case PLIANT_TM_TYPE_VERDICT: ++counts.verdict; break;
    case PLIANT_TM_TYPE_PARTICLES: ++counts.particles; break;
    case PLIANT_TM_TYPE_COUNTERS: ++counts.counters; break;
    default: break;  // the decoder delivers only the four types
  }
}

}  // namespace

const char* stream_end_text(StreamEnd end) {
  switch (end) {
    case StreamEnd::end_of_input: return "end of input";
    case StreamEnd::count: return "count reached";
    case StreamEnd::duration: return "duration reached";
    case StreamEnd::stopped: return "stopped";
    case StreamEnd::hangup: return "device hung up";
    case StreamEnd::read_error: return "read error";
  }
  return "unknown";
}

std::uint64_t StreamResult::dropped() const {
  const pliant_tm_decoder_counters_t& c = decoder;
  return std::uint64_t{c.cobs_error} + c.crc_mismatch + c.oversize + c.short_packet + c.version + c.bad_length +
         c.out_of_range + c.unknown_type + c.truncated;
}

StreamResult read_telemetry(ByteSource& source, const StreamLimits& limits,
                            const std::function<void(const pliant_tm_message_t&)>& on_message,
                            const std::function<bool()>& should_stop) {
  using Clock = std::chrono::steady_clock;
  const auto decoder = std::make_unique<pliant_tm_decoder_t>();
  pliant_tm_decoder_init(decoder.get());
  std::vector<std::uint8_t> buffer(kReadBytes);
  StreamResult result;
  const Clock::time_point start = Clock::now();
  const auto elapsed_s = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };

  bool done = false;
  while (!done) {
    if (should_stop && should_stop()) {
      result.end = StreamEnd::stopped;
      break;
    }
    const double left_s = limits.max_duration_s - elapsed_s();
    if (!(left_s > 0.0)) {
      result.end = StreamEnd::duration;
      break;
    }
    const int timeout_ms = left_s * 1e3 < kPollMs ? static_cast<int>(std::ceil(left_s * 1e3)) : kPollMs;
    ReadResult read;
    try {
      read = source.read(buffer.data(), buffer.size(), timeout_ms);
    } catch (const std::exception& error) {
      result.end = StreamEnd::read_error;
      result.error = error.what();
      break;
    }
    if (read.status == ReadStatus::end || read.status == ReadStatus::hangup) {
      result.end = read.status == ReadStatus::end ? StreamEnd::end_of_input : StreamEnd::hangup;
      break;
    }
    if (read.status != ReadStatus::data) continue;
    result.bytes += read.bytes;
    const std::uint8_t* data = buffer.data();
    std::size_t left = read.bytes;
    while (left > 0) {
      pliant_tm_message_t message;
      std::size_t used = 0;
      const int got = pliant_tm_decoder_push(decoder.get(), data, left, &used, &message);
      data += used;
      left -= used;
      if (got != 1) continue;
      count(result.messages, message.header.type);
      on_message(message);
      if (limits.max_messages > 0 && result.messages.total() >= limits.max_messages) {
        result.end = StreamEnd::count;
        done = true;
        break;
      }
    }
  }
  pliant_tm_decoder_finish(decoder.get());
  result.decoder = decoder->counters;
  result.elapsed_s = elapsed_s();
  return result;
}

}  // namespace pliant::host::telemetry
