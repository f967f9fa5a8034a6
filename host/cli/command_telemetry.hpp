// `pliant telemetry (--serial DEV [--baud B] | --udp PORT [--bind ADDR] | --file F)
//  [-o OUT.jsonl | --recording DIR [--length-unit m|px]] [--count N] [--duration S]`:
// decodes the firmware's telemetry stream (docs/telemetry.md) to JSON lines or a recording.
#pragma once

#include <cstdint>
#include <string>

#include <CLI/CLI.hpp>

namespace pliant::cli {

class TelemetryCommand {
 public:
  /// Registers `telemetry` on `parent`.
  explicit TelemetryCommand(CLI::App& parent);

  bool selected() const { return app_->parsed(); }
  /// Runs after a successful parse; throws on failure (see exit_status.hpp for the mapping).
  int run() const;

 private:
  CLI::App* app_ = nullptr;
  std::string serial_;
  int baud_ = 115200;
  int udp_port_ = 0;
  std::string bind_ = "127.0.0.1";
  std::string file_;
  std::string output_;
  std::string recording_;
  std::string length_unit_ = "m";
  std::int64_t count_ = 0;
  double duration_s_ = 0.0;
};

}  // namespace pliant::cli
