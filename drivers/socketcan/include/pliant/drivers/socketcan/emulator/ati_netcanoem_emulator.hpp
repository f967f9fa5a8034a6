// pliant socketcan driver, emulator: an ATI F/T sensor with a NETCANOEM board on the far end
// of a CanTransport (protocol: docs/drivers/socketcan.md). For tests, and for HIL rigs that
// run the real driver against a sensor that is not there: put the emulator on one end of a
// SeqpacketCanTransport pair (or on a second RawCanTransport on the same vcan/can bus) and
// step it from the rig's loop.
//
// service() answers every queued request the way the board does: READ_SG with its two frames
// (status, SG0, SG2, SG4 / SG1, SG3, SG5), READ_MATRIX with three frames, SET_ACTIVE_CALIBRATION
// with the echo of the active index, READ_COUNTS_PER_UNIT, READ_UNIT_CODES, READ_SERIAL_NUMBER,
// READ_FIRMWARE_VERSION, READ_DIAGNOSTIC_ADC, SET_BASE_ID and SET_BAUD_RATE with an ack; RESET
// has no answer. Requests for another base ID, error frames and malformed requests (wrong DLC,
// axis > 5) are counted and not answered.
// Fault knobs (faults()): mute, halves swapped, dropped or duplicated halves, a refused
// calibration index; and direct injection: any raw frame, error frames (bus-off, restart...),
// disconnect (closes the link).
// Not real-time code, but allocation-free; single-threaded.
#pragma once

#include <cstdint>

#include "pliant/drivers/socketcan/ati_netcanoem_protocol.hpp"
#include "pliant/drivers/socketcan/can_transport.hpp"

namespace pliant::drivers::socketcan {

struct AtiEmulatorConfig {
  std::uint8_t base_id = 0x20;
  ati::Calibration calibration;         ///< what the matrix, counts and units requests answer
  std::uint8_t calibration_slots = 16;  ///< indices >= this are refused (the echo keeps the active one)
  char serial[8] = {'F', 'T', '0', '0', '4', '2', '1', '7'};
  std::uint8_t firmware_major = 2, firmware_minor = 1;
  std::uint16_t firmware_build = 300;
};

struct AtiEmulatorFaults {
  bool mute = false;               ///< consume requests, answer nothing
  bool swap_halves = false;        ///< send the second gauge frame before the first
  int drop_first_halves = 0;       ///< omit the first gauge frame of the next N READ_SG answers
  int drop_second_halves = 0;      ///< omit the second gauge frame of the next N READ_SG answers
  int duplicate_first_halves = 0;  ///< send the first gauge frame twice in the next N answers
  int wrong_dlc_answers = 0;       ///< next N READ_SG answers: the second frame with DLC 5 instead of 6
};

struct AtiEmulatorCounters {
  std::uint64_t requests = 0;        ///< requests for this base ID
  std::uint64_t gauge_requests = 0;  ///< READ_SG
  std::uint64_t matrix_requests = 0;
  std::uint64_t calibration_requests = 0;
  std::uint64_t resets = 0;
  std::uint64_t ignored_frames = 0;  ///< other base IDs, error frames, malformed requests
  std::uint64_t frames_sent = 0;
  std::uint64_t send_failures = 0;
};

class AtiNetCanEmulator {
 public:
  AtiNetCanEmulator(CanTransport& link, const AtiEmulatorConfig& config) noexcept;
  /// Talk through another transport from now on (e.g. after the listener accepted a reconnect).
  void attach(CanTransport& link) noexcept { link_ = &link; }

  /// The raw strain-gauge counts SG0..SG5 the next READ_SG answers carry.
  void set_gauges(const std::int16_t gauges[6]) noexcept;
  /// The status word the next READ_SG answers carry.
  void set_status(std::uint16_t status) noexcept { status_ = status; }
  AtiEmulatorFaults& faults() noexcept { return faults_; }
  /// The emulated board's settings (calibration, serial...); changes apply to later answers.
  AtiEmulatorConfig& config() noexcept { return config_; }

  /// Answers up to `max_requests` queued requests. Returns how many frames were read.
  int service(int max_requests = 256) noexcept;

  CanIo send_raw(const CanFrame& frame) noexcept;
  /// An error frame (classes: kCanErr*; data8 may be null).
  CanIo send_error(std::uint32_t classes, const std::uint8_t* data8 = nullptr) noexcept;
  /// Closes the link: the driver sees the peer gone.
  void disconnect() noexcept { link_->close(); }

  std::uint8_t active_calibration() const noexcept { return active_calibration_; }
  std::uint8_t base_id() const noexcept { return base_id_; }
  const AtiEmulatorCounters& counters() const noexcept { return counters_; }

 private:
  void answer(const CanFrame& request) noexcept;
  void answer_gauges() noexcept;
  void send(ati::Opcode op, const std::uint8_t* payload, std::uint8_t dlc) noexcept;

  CanTransport* link_;
  AtiEmulatorConfig config_;
  AtiEmulatorFaults faults_;
  AtiEmulatorCounters counters_;
  std::int16_t gauges_[6] = {0, 0, 0, 0, 0, 0};
  std::uint16_t status_ = 0;
  std::uint8_t active_calibration_ = 0;
  std::uint8_t base_id_ = 0;
};

}  // namespace pliant::drivers::socketcan
