// pliant socketcan driver, emulator: a Robotous RFT sensor on the far end of a CanTransport
// (protocol: docs/drivers/socketcan.md). For tests and HIL rigs, like AtiNetCanEmulator.
//
// service() handles queued commands: 10 (one F/T packet), 11 (start streaming), 12 (stop),
// 17 (bias on: zero on the current load; off: absolute), 15 (set output rate; answered with
// [15, 1] - the real answer's layout is not documented in the sources, the driver ignores it),
// 16 (get output rate: [16, code]). Other codes and frames on other IDs are counted, not
// answered. stream(n) sends n F/T packets while streaming (the caller's loop is the sensor's
// clock). A packet is [cmd, Fx..Tz int16 BE, overload, 0, 0] over the two response IDs.
// Fault knobs: dropped first/second halves, swapped halves, wrong DLC, overload byte; raw
// frames, error frames and disconnect as for the ATI emulator.
#pragma once

#include <cstdint>

#include "pliant/drivers/socketcan/can_transport.hpp"
#include "pliant/drivers/socketcan/robotous_rft_protocol.hpp"

namespace pliant::drivers::socketcan {

struct RftEmulatorConfig {
  rft::Ids ids;
  double force_divider = 50.0;
  double torque_divider = 2000.0;
};

struct RftEmulatorFaults {
  bool mute = false;           ///< consume commands, answer and stream nothing
  int drop_first_halves = 0;   ///< next N packets without their first frame
  int drop_second_halves = 0;  ///< next N packets without their second frame
  int swap_halves = 0;         ///< next N packets with the second frame first
  int wrong_dlc = 0;           ///< next N packets with a 7-byte second frame
};

struct RftEmulatorCounters {
  std::uint64_t commands = 0;        ///< frames on the command ID
  std::uint64_t stream_starts = 0;   ///< command 11
  std::uint64_t stream_stops = 0;    ///< command 12
  std::uint64_t bias_commands = 0;   ///< command 17
  std::uint64_t rate_commands = 0;   ///< command 15
  std::uint64_t packets_sent = 0;    ///< F/T packets (one or both halves sent)
  std::uint64_t ignored_frames = 0;  ///< other IDs, unknown codes, error frames, DLC != 8
  std::uint64_t send_failures = 0;
};

class RobotousRftEmulator {
 public:
  RobotousRftEmulator(CanTransport& link, const RftEmulatorConfig& config) noexcept;
  void attach(CanTransport& link) noexcept { link_ = &link; }

  /// The sensor's load in raw counts (before the device bias).
  void set_raw(const std::int16_t raw[6]) noexcept;
  /// The load in N and N m, rounded to counts with the dividers and saturated to int16.
  void set_wrench(const double wrench[6]) noexcept;
  void set_overload(std::uint8_t flags) noexcept { overload_ = flags; }
  RftEmulatorFaults& faults() noexcept { return faults_; }

  /// Handles up to `max_commands` queued frames. Returns how many frames were read.
  int service(int max_commands = 256) noexcept;
  /// Sends `packets` F/T packets if streaming (none otherwise). Returns how many were sent.
  int stream(int packets = 1) noexcept;

  CanIo send_raw(const CanFrame& frame) noexcept;
  CanIo send_error(std::uint32_t classes, const std::uint8_t* data8 = nullptr) noexcept;
  void disconnect() noexcept { link_->close(); }

  bool streaming() const noexcept { return streaming_; }
  bool bias_active() const noexcept { return bias_active_; }
  int output_rate_code() const noexcept { return rate_code_; }
  const RftEmulatorCounters& counters() const noexcept { return counters_; }

 private:
  void handle(const CanFrame& frame) noexcept;
  void send_packet(std::uint8_t command) noexcept;
  void send_response(std::uint8_t b0, std::uint8_t b1) noexcept;
  void send(const CanFrame& frame) noexcept;

  CanTransport* link_;
  RftEmulatorConfig config_;
  RftEmulatorFaults faults_;
  RftEmulatorCounters counters_;
  std::int16_t raw_[6] = {0, 0, 0, 0, 0, 0};
  std::int16_t bias_[6] = {0, 0, 0, 0, 0, 0};
  std::uint8_t overload_ = 0;
  bool streaming_ = false;
  bool bias_active_ = false;
  int rate_code_ = 0;
};

}  // namespace pliant::drivers::socketcan
