// pliant socketcan driver: a Robotous RFT sensor (RFT40/60/80, CAN), as a hal::ForceTorqueSensor.
//
// Lifecycle
//   configure  checks the config, sets the receive filter (the two response IDs) and opens the
//              transport; fails with the transport's status when it cannot. Sends nothing.
//   start      discards frames queued while inactive; the first read sends the start commands.
//   read       (bounded, non-blocking, allocation-free, noexcept) drains up to
//              link.max_frames_per_read frames and returns:
//              ok             the newest complete F/T packet (earlier ones in the same drain are
//                             superseded and show as a sequence gap, counted as dropped)
//              no_data        nothing new
//              timeout        no F/T packet for timeout_s (since the stream was requested or
//                             the last packet); the start command is then repeated every
//                             timeout_s (stream_requests counts them), in case the sensor
//                             rebooted or missed it
//              bus_off, disconnected, io_error   as for every CAN device (can_link.hpp)
//   stop       sends the stop command (12; best effort: the link may be down).
//   cleanup    closes the transport.
// Start commands, in the first read after start and after every reconnect: set output rate
//   (15, when output_rate_code >= 0), set bias (17 on, when bias_on_start and only after start,
//   never after a reconnect: re-zeroing under load would hide the load), start streaming (11).
// Sample
//   wrench       raw / force_divider (N), raw / torque_divider (N m), sensor frame, tared on
//                the sensor (device bias; tare() / clear_tare()).
//   stamp_s      kernel receive time of the packet's second frame on the injected clock.
//   status_bits  an overload byte != 0 sets kFtAdcHigh | kFtAnyError (the reading is clipped:
//                kFtAdcHigh is in kFtFaultMask); kFtCanBusError when error frames arrived
//                since the previous sample. The raw byte is last_overload().
// Other responses (byte 0 not 10/11: answers to commands like 15) are consumed and counted.
// Thread safety: one thread drives the device.
#pragma once

#include <cstdint>

#include "pliant/drivers/socketcan/can_link.hpp"
#include "pliant/drivers/socketcan/robotous_rft_protocol.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/force_torque.hpp"

namespace pliant::drivers::socketcan {

struct RobotousRftConfig {
  rft::Ids ids;                    ///< command and response IDs (standard, distinct)
  double force_divider = 50.0;     ///< > 0: raw counts per N (model dependent)
  double torque_divider = 2000.0;  ///< > 0: raw counts per N m (model dependent)
  int output_rate_code = -1;       ///< -1: leave the sensor's rate; 0..8: set it at start (see protocol)
  bool bias_on_start = false;      ///< zero the sensor on its current load at start
  double timeout_s = 0.1;          ///< > 0: no packet for this long -> timeout (and the stream is requested again)
  CanLinkConfig link;
};

struct RftCounters {
  std::uint64_t stream_requests = 0;     ///< start-streaming commands sent (first and repeated)
  std::uint64_t commands_sent = 0;       ///< every command frame sent
  std::uint64_t send_failures = 0;       ///< commands the link could not send
  std::uint64_t complete_packets = 0;    ///< F/T packets reassembled
  std::uint64_t overload_packets = 0;    ///< ... with a non-zero overload byte
  std::uint64_t incomplete_packets = 0;  ///< first halves discarded (second lost) or seconds without first
  std::uint64_t foreign_frames = 0;      ///< frames with another ID (dropped)
  std::uint64_t wrong_dlc = 0;           ///< response IDs with DLC != 8 (dropped)
  std::uint64_t other_responses = 0;     ///< complete packets that are not F/T data (consumed)
  std::uint64_t dropped_frames() const noexcept { return foreign_frames + wrong_dlc + incomplete_packets; }
};

class RobotousRftForceTorque final : public hal::ForceTorqueSensor {
 public:
  RobotousRftForceTorque(CanTransport& transport, const hal::Clock& clock, const RobotousRftConfig& config) noexcept;

  /// Sends the bias command (17, on): the sensor zeroes on its current load. ok, wrong_state
  /// (not active), or the send failure (io_error, disconnected). Real-time safe.
  hal::HalStatus tare() noexcept;
  /// Sends the bias command off (17, 0): readings are absolute again.
  hal::HalStatus clear_tare() noexcept;

  bool streaming_requested() const noexcept { return stream_requested_; }
  std::uint8_t last_overload() const noexcept { return last_overload_; }
  /// The raw packet values behind the last delivered reading.
  const rft::FtPacket& last_packet() const noexcept { return last_packet_; }
  const RftCounters& protocol_counters() const noexcept { return counters_; }
  const CanLinkCounters& link_counters() const noexcept { return link_.counters(); }
  bool bus_off() const noexcept { return link_.bus_off(); }
  /// The last SocketCAN error frame's report (all zero if none since configure).
  const CanErrorReport& last_can_error() const noexcept { return link_.last_error(); }
  const RobotousRftConfig& config() const noexcept { return config_; }

 protected:
  hal::HalStatus on_configure() override;
  hal::HalStatus on_start() noexcept override;
  hal::HalStatus on_stop() noexcept override;
  hal::HalStatus on_cleanup() noexcept override;
  hal::HalStatus on_read(hal::WrenchReading& out) noexcept override;

 private:
  hal::HalStatus send_command(std::uint8_t code, std::uint8_t arg) noexcept;
  void send_pending(double now) noexcept;
  void handle_frame(const CanFrame& frame, double stamp_s, double now, hal::WrenchReading& sample, bool& have) noexcept;

  const hal::Clock& clock_;
  RobotousRftConfig config_;
  CanLink link_;
  RftCounters counters_;
  rft::PacketAssembler assembler_;
  rft::FtPacket last_packet_;
  std::uint8_t last_overload_ = 0;
  bool stream_requested_ = false;
  std::uint8_t pending_ = 0;  ///< commands still to send (rate, bias, stream)
  double requested_s_ = 0;
  double last_sample_s_ = 0;
  std::uint64_t sequence_ = 0;
};

}  // namespace pliant::drivers::socketcan
