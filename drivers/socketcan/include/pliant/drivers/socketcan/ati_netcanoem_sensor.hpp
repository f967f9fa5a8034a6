// pliant socketcan driver: an ATI F/T sensor with the NETCANOEM CAN board, as a
// hal::ForceTorqueSensor.
//
// Lifecycle
//   configure  checks the config, sets the receive filter (the 13 response opcodes of the base
//              ID) and opens the transport; fails with the transport's status (unsupported,
//              disconnected, io_error) when it cannot. Sends nothing.
//   start      discards frames queued while inactive and starts the setup sequence; all I/O
//              happens inside read(), so start never blocks.
//   read       (bounded, non-blocking, allocation-free, noexcept) drains up to
//              link.max_frames_per_read frames, advances the setup or the polling, and returns:
//              ok             the newest complete sample (earlier ones in the same drain are
//                             superseded and show as a sequence gap, counted as dropped)
//              no_data        nothing new (setup still running, or the poll not answered yet)
//              timeout        no complete sample for timeout_s (since start or the last sample)
//              bus_off        the controller is bus-off (error frame); the bus must restart
//              disconnected   the transport is gone; reopened every link.reconnect_interval_s
//              io_error       the transport failed otherwise
//              device_fault   setup failed on what the sensor reported (setup_error() says
//                             what: calibration refused, zero counts, unknown units, NaN in
//                             the matrix); setup is retried every link.reconnect_interval_s
//   stop       forgets the outstanding poll.
//   cleanup    closes the transport.
// Setup sequence (docs/drivers/socketcan.md): SET_ACTIVE_CALIBRATION (the echo must match),
//   then, when calibration_from_device, READ_MATRIX for the 6 axes, READ_COUNTS_PER_UNIT and
//   READ_UNIT_CODES; then READ_SERIAL_NUMBER and READ_FIRMWARE_VERSION (info()). A step not
//   answered within response_timeout_s is sent again. After a reconnect the sequence runs again
//   (the sensor may have been power-cycled and lost its active calibration).
// Polling: one READ_SG at a time, at most one per poll_period_s; the next poll goes out in the
//   read that completes the previous one. A poll not answered in full within
//   response_timeout_s is abandoned (unanswered_polls, and incomplete_samples if half arrived).
//
// Sample
//   wrench     (N, N m, sensor frame) = scaling * (gauges - gauge bias), the unit codes
//              converted to SI.
//   stamp_s    the kernel receive time of the frame that completed the sample, on the injected
//              clock (link.use_receive_timestamps; else the clock at read time).
//   sequence   +1 per complete sample delivered or superseded (not for samples withheld by
//              tare-on-start or by the restart hold-off).
//   status_bits  the sensor's status word as is (the hal's F/T bits are the NETCANOEM layout:
//              bits in kFtFaultMask mean "do not trust", the rest are informational), plus
//              kFtCanBusError when error frames arrived since the previous sample.
// Tare (host-side; the protocol has none): the gauge bias is the mean of the next N raw samples
//   whose status word is 0 (samples with any status bit are skipped). tare(n) keeps delivering
//   samples with the old bias until the mean is complete; tare_samples_on_start withholds
//   samples (no_data) until the first tare is complete.
// Thread safety: one thread drives the device (the hal's rule); not internally locked.
#pragma once

#include <cstdint>

#include "pliant/drivers/socketcan/ati_netcanoem_protocol.hpp"
#include "pliant/drivers/socketcan/can_link.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/force_torque.hpp"

namespace pliant::drivers::socketcan {

inline constexpr int kMaxTareSamples = 100000;

struct AtiNetCanConfig {
  std::uint8_t base_id = 0x20;                ///< 0..0x7F (the board's switch/EEPROM setting)
  std::uint8_t calibration_index = 0;         ///< 0..15
  double poll_period_s = 0.0;                 ///< >= 0: minimum time between READ_SG polls (0: every read)
  double response_timeout_s = 0.02;           ///< > 0: a request without its full answer is sent again
  double timeout_s = 0.1;                     ///< > 0: no complete sample for this long -> timeout
  bool calibration_from_device = true;        ///< read matrix, counts and units from the sensor
  ati::Calibration calibration;               ///< used when !calibration_from_device (from the calibration file)
  double gauge_bias[6] = {0, 0, 0, 0, 0, 0};  ///< initial tare, gauge counts (finite)
  int tare_samples_on_start = 0;  ///< 0..kMaxTareSamples: tare after start's setup (not after a reconnect's)
  CanLinkConfig link;
};

enum class AtiSetupError : std::uint8_t {
  none = 0,
  calibration_refused,  ///< SET_ACTIVE_CALIBRATION echoed another index
  bad_calibration,      ///< see calibration_error()
};

/// What the sensor told about itself during setup.
struct AtiDeviceInfo {
  char serial[9] = {};  ///< NUL-terminated copy of the 8 serial bytes
  std::uint8_t firmware_major = 0, firmware_minor = 0;
  std::uint16_t firmware_build = 0;
  ati::Calibration calibration;  ///< the calibration in use
};

/// Protocol counters, monotonic, reset by configure().
struct AtiCounters {
  std::uint64_t polls_sent = 0;          ///< READ_SG requests sent
  std::uint64_t unanswered_polls = 0;    ///< polls abandoned after response_timeout_s
  std::uint64_t incomplete_samples = 0;  ///< half samples discarded (other half lost or duplicated)
  std::uint64_t complete_samples = 0;    ///< both halves received
  std::uint64_t foreign_frames = 0;      ///< frames with another ID (dropped)
  std::uint64_t unknown_opcodes = 0;     ///< our base ID, opcode without a response (dropped)
  std::uint64_t wrong_dlc = 0;           ///< our base ID, known opcode, wrong length (dropped)
  std::uint64_t unexpected_frames = 0;   ///< valid responses nobody was waiting for (dropped)
  std::uint64_t setup_requests = 0;      ///< setup requests sent (including repeats)
  std::uint64_t setup_retries = 0;       ///< setup requests repeated after response_timeout_s
  std::uint64_t setups_completed = 0;
  std::uint64_t setup_failures = 0;  ///< setups ended by a setup_error
  std::uint64_t tares_completed = 0;
  std::uint64_t send_failures = 0;  ///< requests the link could not send
  /// Every frame this device dropped as malformed or unexpected.
  std::uint64_t dropped_frames() const noexcept {
    return foreign_frames + unknown_opcodes + wrong_dlc + unexpected_frames;
  }
};

class AtiNetCanForceTorque final : public hal::ForceTorqueSensor {
 public:
  /// `transport` and `clock` must outlive the device; the transport is this device's alone.
  AtiNetCanForceTorque(CanTransport& transport, const hal::Clock& clock, const AtiNetCanConfig& config) noexcept;

  /// Starts a tare over the next `samples` good samples (1..kMaxTareSamples; invalid_argument
  /// otherwise; wrong_state when unconfigured). Real-time safe.
  hal::HalStatus tare(int samples) noexcept;
  bool tare_pending() const noexcept { return tare_target_ > 0; }
  /// Replaces the gauge bias (counts; finite, else invalid_argument). Cancels a pending tare.
  hal::HalStatus set_gauge_bias(const double bias[6]) noexcept;
  const double* gauge_bias() const noexcept { return bias_; }

  /// True once setup finished (calibration known) and polling runs.
  bool ready() const noexcept { return phase_ == Phase::polling; }
  AtiSetupError setup_error() const noexcept { return setup_error_; }
  ati::CalibrationError calibration_error() const noexcept { return calibration_error_; }
  const AtiDeviceInfo& info() const noexcept { return info_; }
  /// The raw gauge sample behind the last delivered reading.
  const ati::GaugeSample& last_gauges() const noexcept { return last_gauges_; }
  const AtiCounters& protocol_counters() const noexcept { return counters_; }
  const CanLinkCounters& link_counters() const noexcept { return link_.counters(); }
  bool bus_off() const noexcept { return link_.bus_off(); }
  /// The last SocketCAN error frame's report (all zero if none since configure).
  const CanErrorReport& last_can_error() const noexcept { return link_.last_error(); }
  const AtiNetCanConfig& config() const noexcept { return config_; }

 protected:
  hal::HalStatus on_configure() override;
  hal::HalStatus on_start() noexcept override;
  hal::HalStatus on_stop() noexcept override;
  hal::HalStatus on_cleanup() noexcept override;
  hal::HalStatus on_read(hal::WrenchReading& out) noexcept override;

 private:
  enum class Phase : std::uint8_t { setup, polling, failed };
  enum class Step : std::uint8_t {
    set_calibration,
    read_matrix,
    read_counts,
    read_units,
    read_serial,
    read_firmware,
    done
  };

  void restart_setup(double now) noexcept;
  void handle_frame(const CanFrame& frame, double stamp_s, double now, hal::WrenchReading& sample, bool& have) noexcept;
  void handle_setup_response(const ati::Response& r, double now) noexcept;
  void advance_setup(double now) noexcept;
  void finish_setup(double now) noexcept;
  void fail_setup(AtiSetupError e, double now) noexcept;
  bool send_request(ati::Opcode op, std::uint8_t arg) noexcept;
  void send_step(double now) noexcept;
  void on_gauges(const ati::GaugeSample& g, double stamp_s, hal::WrenchReading& sample, bool& have) noexcept;
  void drive_setup(double now) noexcept;
  void drive_polling(double now) noexcept;

  const hal::Clock& clock_;
  AtiNetCanConfig config_;
  CanLink link_;
  AtiCounters counters_;
  AtiDeviceInfo info_;
  ati::Scaling scaling_;
  ati::GaugeAssembler assembler_;
  ati::GaugeSample last_gauges_;
  Phase phase_ = Phase::setup;
  Step step_ = Step::set_calibration;
  int matrix_row_ = 0;
  std::uint8_t matrix_parts_ = 0;  ///< bits 0..2: the three frames of the current row
  bool step_sent_ = false;
  double step_sent_s_ = 0;
  AtiSetupError setup_error_ = AtiSetupError::none;
  ati::CalibrationError calibration_error_ = ati::CalibrationError::none;
  double failed_at_s_ = 0;
  bool poll_outstanding_ = false;
  double poll_sent_s_ = 0;
  bool polled_once_ = false;
  double last_sample_s_ = 0;  ///< device-clock time of the last complete sample (or of start)
  std::uint64_t sequence_ = 0;
  double bias_[6] = {0, 0, 0, 0, 0, 0};
  int tare_target_ = 0;
  int tare_count_ = 0;
  double tare_sum_[6] = {0, 0, 0, 0, 0, 0};
  bool tare_blocks_ = false;       ///< withhold samples until the running tare completes
  bool tare_after_setup_ = false;  ///< the setup in progress follows start() (tare_samples_on_start applies)
};

}  // namespace pliant::drivers::socketcan
