// The one-line account of a telemetry run.
#include <cstdio>
#include <string>

#include "pliant/host/telemetry/stream.hpp"

namespace pliant::host::telemetry {

std::string stream_summary(const StreamResult& r) {
  const MessageCounts& m = r.messages;
  const pliant_tm_decoder_counters_t& d = r.decoder;
  const auto n = [](std::uint64_t value) { return std::to_string(value); };
  char seconds[32];
  std::snprintf(seconds, sizeof seconds, "%.2f", r.elapsed_s);
  std::string text = "messages " + n(m.total()) + " (estimate " + n(m.estimate) + ", verdict " + n(m.verdict) +
                     ", particles " + n(m.particles) + ", counters " + n(m.counters) + "); dropped " + n(r.dropped()) +
                     " (cobs_error " + n(d.cobs_error) + ", crc_mismatch " + n(d.crc_mismatch) + ", oversize " +
                     n(d.oversize) + ", short_packet " + n(d.short_packet) + ", version " + n(d.version) +
                     ", bad_length " + n(d.bad_length) + ", out_of_range " + n(d.out_of_range) + ", unknown_type " +
                     n(d.unknown_type) + ", truncated " + n(d.truncated) + "); sequence: " + n(d.seq_missed) +
                     " missed, " + n(d.seq_backward) + " backward; " + n(r.bytes) + " bytes in " + seconds + " s; " +
                     stream_end_text(r.end);
  return text;
}

}  // namespace pliant::host::telemetry
