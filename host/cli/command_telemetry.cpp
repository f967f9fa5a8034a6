#include "command_telemetry.hpp"

#include <signal.h>

#include <cmath>
#include <csignal>
#include <filesystem>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>

#include "exit_status.hpp"
#include "pliant/host/telemetry/json_lines.hpp"
#include "pliant/host/telemetry/recording_builder.hpp"
#include "pliant/host/telemetry/stream.hpp"
#include "pliant/host/telemetry/transports.hpp"
#include "telemetry_outputs.hpp"

namespace pliant::cli {
namespace {

namespace tm = host::telemetry;

volatile std::sig_atomic_t g_stop_requested = 0;

extern "C" void request_stop(int /*signal*/) { g_stop_requested = 1; }

// SIGINT and SIGTERM end the stream like its end of input (outputs are still written) for as
// long as this object lives; the previous handlers come back afterwards.
class StopOnSignals {
 public:
  StopOnSignals() {
    g_stop_requested = 0;
    struct sigaction action {};
    action.sa_handler = request_stop;
    sigemptyset(&action.sa_mask);
    action.sa_flags = 0;  // no SA_RESTART: a blocked poll() returns at once
    sigaction(SIGINT, &action, &old_int_);
    sigaction(SIGTERM, &action, &old_term_);
  }
  ~StopOnSignals() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  StopOnSignals(const StopOnSignals&) = delete;
  StopOnSignals& operator=(const StopOnSignals&) = delete;

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

std::unique_ptr<tm::ByteSource> open_source(const CLI::App& app, const std::string& serial, int baud, int udp_port,
                                            const std::string& bind, const std::string& file) {
  try {
    if (app.count("--serial") > 0) return std::make_unique<tm::SerialSource>(serial, baud);
    if (app.count("--udp") > 0) return std::make_unique<tm::UdpSource>(bind, udp_port);
    return std::make_unique<tm::FileSource>(file);
  } catch (const std::invalid_argument& e) {
    throw UsageError(e.what());
  }
}

std::string frame_summary(const tm::ParticleFrameCounts& c) {
  return "particle frames " + std::to_string(c.kept) + " kept, " + std::to_string(c.dropped()) +
         " dropped (incomplete " + std::to_string(c.incomplete) + ", before_rest " + std::to_string(c.before_rest) +
         ", shape " + std::to_string(c.shape) + ", time " + std::to_string(c.time) + ")";
}

}  // namespace

TelemetryCommand::TelemetryCommand(CLI::App& parent) {
  app_ = parent.add_subcommand("telemetry", "Decode the firmware's telemetry stream to JSON lines or a recording");
  app_->footer(
      "Reads frames of the telemetry wire format (docs/telemetry.md: COBS, CRC-16, version 1) from a serial port, "
      "a UDP port or a file, and writes one JSON object per message (estimate, verdict, particles, counters; "
      "\"type\", \"seq\", \"stamp_us\" and the fields by name, NaN and infinities as null) to standard output or "
      "-o FILE. With --recording, writes a recording-v1 directory from the particles messages instead: one frame "
      "per complete tracker frame, t = stamp_us / 1e6 s, the first frame observing every particle as the rest "
      "shape, predicted and lost particles unobserved.\n"
      "Reading stops at the end of the file, after --count messages, after --duration seconds, or on Ctrl-C "
      "(SIGINT) or SIGTERM; outputs are then completed (a file or recording appears only whole). Frames that cannot "
      "be used are dropped and counted: the last line on stderr gives messages by type and drops by reason.\n"
      "Exit status: 0 the stream was read (drops are counted, not failures), 1 the source or output cannot be "
      "opened, read or written (what was decoded before a read error is still written), or --recording found no "
      "complete particle frame, 2 bad options or a non-empty --recording directory.");
  auto* serial = app_->add_option("--serial", serial_, "Serial device (raw 8N1, no flow control), e.g. /dev/ttyACM0")
                     ->type_name("DEV");
  auto* udp = app_->add_option("--udp", udp_port_, "Listen for datagrams on this UDP port")
                  ->type_name("PORT")
                  ->check(CLI::Range(1, 65535));
  auto* file = app_->add_option("--file", file_, "Read a captured stream; '-' for standard input")->type_name("F");
  serial->excludes(udp)->excludes(file);
  udp->excludes(file);
  app_->add_option("--baud", baud_, "Serial baud rate")->type_name("B")->capture_default_str()->needs(serial);
  app_->add_option("--bind", bind_, "UDP address to bind (numeric; 0.0.0.0 for every interface)")
      ->type_name("ADDR")
      ->capture_default_str()
      ->needs(udp);
  auto* output =
      app_->add_option("-o,--output", output_, "JSON lines file (default: standard output)")->type_name("OUT.jsonl");
  auto* recording = app_->add_option("--recording", recording_, "Write a recording directory instead of JSON lines")
                        ->type_name("DIR");
  output->excludes(recording);
  app_->add_option("--length-unit", length_unit_, "The recording's length_unit: the unit of the particle positions")
      ->type_name("m|px")
      ->check(CLI::IsMember({"m", "px"}))
      ->capture_default_str()
      ->needs(recording);
  app_->add_option("--count", count_, "Stop after N decoded messages (any type)")
      ->type_name("N")
      ->check(CLI::PositiveNumber);
  app_->add_option("--duration", duration_s_, "Stop after S seconds")->type_name("S");
}

int TelemetryCommand::run() const {
  if (app_->count("--serial") + app_->count("--udp") + app_->count("--file") != 1) {
    throw UsageError("give one source: --serial DEV, --udp PORT or --file F");
  }
  tm::StreamLimits limits;
  if (app_->count("--duration") > 0) {
    if (!(std::isfinite(duration_s_) && duration_s_ > 0.0)) throw UsageError("--duration must be > 0 seconds");
    limits.max_duration_s = duration_s_;
  }
  if (app_->count("--count") > 0) limits.max_messages = static_cast<std::uint64_t>(count_);
  const bool to_recording = app_->count("--recording") > 0;
  if (to_recording) check_new_recording_directory(recording_);

  const std::unique_ptr<tm::ByteSource> source = open_source(*app_, serial_, baud_, udp_port_, bind_, file_);
  const bool live = app_->count("--file") == 0;
  std::unique_ptr<JsonLinesOutput> json;
  if (!to_recording) json = std::make_unique<JsonLinesOutput>(output_, live);
  if (live) {
    report_error("pliant telemetry", "reading " + source->describe() + " (Ctrl-C to stop)");
  }

  tm::RecordingBuilder builder;
  tm::StreamResult result;
  {
    const StopOnSignals stop_on_signals;
    result = tm::read_telemetry(
        *source, limits,
        [&](const pliant_tm_message_t& message) {
          if (json) {
            json->write(tm::message_json(message));
          } else if (message.header.type == PLIANT_TM_TYPE_PARTICLES) {
            builder.add(message.body.particles, message.header.stamp_us);
          }
        },
        [] { return g_stop_requested != 0; });
  }
  builder.finish();

  std::string summary = tm::stream_summary(result);
  std::string failure = result.end == tm::StreamEnd::read_error ? result.error : "";
  if (json) {
    json->commit();
    if (json->label() != "standard output") summary += "; wrote " + json->label();
  } else {
    summary += "; " + frame_summary(builder.counts());
    if (builder.has_frames()) {
      std::filesystem::path target = std::filesystem::path(recording_).lexically_normal();
      if (!target.has_filename()) target = target.parent_path();
      write_recording_atomically(builder.recording(target.filename().string(), length_unit_), recording_);
      summary += "; wrote " + recording_;
    } else if (failure.empty()) {
      failure = "no complete particle frame observing every particle; nothing written to " + recording_;
    }
  }
  report_error("pliant telemetry", summary);
  if (!failure.empty()) {
    report_error("pliant telemetry", failure);
    return exit_failure;
  }
  return exit_ok;
}

}  // namespace pliant::cli
