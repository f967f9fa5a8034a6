// pliant socketcan driver: the link state both sensor classes share.
//
// A CanLink wraps one CanTransport for one device and owns everything that is not protocol:
// - reconnecting: when the transport is closed (a disconnect), begin_read() tries open() at
//   most once per reconnect_interval_s of the device's clock;
// - draining: next_frame() hands out data frames, at most max_frames_per_read per read, so a
//   read stays bounded when the bus floods; error frames and malformed records are consumed
//   and counted on the way and never reach the protocol;
// - bus state: an error frame with bus-off sets bus_off(); the controller's restart (an
//   error frame with kCanErrRestarted, or back to error-active), or a valid frame from the
//   sensor (note_sensor_frame()), clears it. Every error frame sets the degraded flag, which
//   the device turns into kFtCanBusError on its next sample (take_degraded());
// - hold-off: after a bus restart or a reconnect the next samples_after_restart complete
//   samples are withheld (admit_sample() returns false) so that a half-recovered bus does not
//   deliver a sample taken across the outage;
// - receive stamps: a frame's stamp on the device's Clock is now_s() minus its age, the age
//   being CLOCK_REALTIME now minus the kernel receive time (receive_stamp_s()).
// Real-time safety: every call but configure() is allocation-free, noexcept and bounded.
// Thread safety: one thread (the device's).
#pragma once

#include <cstddef>
#include <cstdint>

#include "pliant/drivers/socketcan/can_error.hpp"
#include "pliant/drivers/socketcan/can_transport.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/status.hpp"

namespace pliant::drivers::socketcan {

struct CanLinkConfig {
  double reconnect_interval_s = 0.5;   ///< > 0: time between reopen attempts while disconnected
  int max_frames_per_read = 64;        ///< 1..4096: frames (of any kind) consumed per read
  bool use_receive_timestamps = true;  ///< stamp samples with the kernel receive time
  double max_receive_age_s = 1.0;      ///< > 0: older receive stamps are not trusted (clock steps)
  int samples_after_restart = 0;       ///< 0..1000 complete samples withheld after a restart/reconnect
};

/// Link-level counters, monotonic, reset by configure().
struct CanLinkCounters {
  std::uint64_t frames_received = 0;     ///< data frames handed to the protocol
  std::uint64_t frames_sent = 0;         ///< frames the transport accepted
  std::uint64_t send_busy = 0;           ///< sends refused: transmit queue full
  std::uint64_t send_errors = 0;         ///< sends that failed otherwise (io_error, disconnected)
  std::uint64_t malformed_records = 0;   ///< transport records that were not a CAN frame
  std::uint64_t receive_errors = 0;      ///< receive calls that failed with io_error
  std::uint64_t error_frames = 0;        ///< every error frame
  std::uint64_t bus_off_events = 0;      ///< transitions into bus-off
  std::uint64_t bus_restarts = 0;        ///< transitions out of bus-off
  std::uint64_t rx_overflows = 0;        ///< error frames reporting lost received frames
  std::uint64_t no_ack = 0;              ///< error frames with kCanErrNoAck (nobody acknowledged)
  std::uint64_t tx_timeouts = 0;         ///< error frames with kCanErrTxTimeout
  std::uint64_t disconnects = 0;         ///< the transport reported the link gone
  std::uint64_t reconnect_attempts = 0;  ///< open() calls while disconnected
  std::uint64_t reconnects = 0;          ///< ... that succeeded
  std::uint64_t held_samples = 0;        ///< complete samples withheld after a restart or reconnect
  std::uint64_t untrusted_stamps = 0;    ///< receive stamps older than max_receive_age_s or in the future
  std::uint64_t budget_exhausted = 0;    ///< reads that stopped at max_frames_per_read (frames may be left)
  std::uint64_t flushed_frames = 0;      ///< data frames discarded by flush() (queued while inactive)
};

/// The capture time on the device clock of a frame received at `rx_realtime_ns` (CLOCK_REALTIME)
/// when the realtime clock reads `realtime_now_ns` and the device clock `now_s`. Falls back to
/// now_s (trusted = false) for an unknown stamp (< 0), a stamp in the future or one older than
/// max_age_s. Pure.
double receive_stamp_s(double now_s, std::int64_t realtime_now_ns, std::int64_t rx_realtime_ns, double max_age_s,
                       bool& trusted) noexcept;

/// Checks a CanLinkConfig: ok or invalid_argument.
hal::HalStatus validate(const CanLinkConfig& config) noexcept;

class CanLink {
 public:
  CanLink(CanTransport& transport, const hal::Clock& clock) noexcept : transport_(transport), clock_(clock) {}

  /// Sets the filter and opens the transport (configure-time; counters reset). Returns the
  /// transport's open() status, or invalid_argument for a bad config or filter. A transport
  /// that is already open (e.g. one end of a socketpair) is used as it is, and cleanup() then
  /// leaves it open.
  hal::HalStatus configure(const CanLinkConfig& config, const std::uint32_t* ids, std::size_t count) noexcept;
  /// Closes the transport if configure() opened it.
  void cleanup() noexcept;
  /// Discards the data frames queued while the device was not reading (at most 4096 records;
  /// start-time). Error frames among them still update the bus state.
  void flush() noexcept;

  /// Start of a read. ok when the link is open (reopened = true if it was just reopened), else
  /// disconnected (a reopen attempt is made when reconnect_interval_s has passed).
  hal::HalStatus begin_read(bool& reopened) noexcept;
  /// The next data frame of this read and its stamp on the device clock. False when the queue
  /// is empty, the budget is used or the link failed (then read_status() says which).
  bool next_frame(CanFrame& frame, double& stamp_s) noexcept;
  /// ok, or disconnected / io_error when next_frame() stopped on a transport failure.
  hal::HalStatus read_status() const noexcept { return read_status_; }

  /// Sends one frame (counted). ok, or the failure mapped: busy -> io_error, disconnected ->
  /// disconnected (the transport is then closed), io_error -> io_error.
  hal::HalStatus send(const CanFrame& frame) noexcept;

  /// A valid frame from the sensor arrived: the bus works (clears bus-off).
  void note_sensor_frame() noexcept;
  bool bus_off() const noexcept { return bus_off_; }
  /// True if an error frame arrived since the last call; clears the flag.
  bool take_degraded() noexcept;
  /// Whether a complete sample may be delivered (false while the post-restart hold-off runs).
  bool admit_sample() noexcept;
  /// Starts the hold-off (samples_after_restart samples) now.
  void begin_holdoff() noexcept { holdoff_ = config_.samples_after_restart; }

  const CanLinkCounters& counters() const noexcept { return counters_; }
  const CanLinkConfig& config() const noexcept { return config_; }
  /// The last error frame's report (all zero if none yet).
  const CanErrorReport& last_error() const noexcept { return last_error_; }
  CanTransport& transport() noexcept { return transport_; }

 private:
  void handle_error_frame(const CanFrame& frame) noexcept;
  void mark_disconnected() noexcept;

  CanTransport& transport_;
  const hal::Clock& clock_;
  CanLinkConfig config_;
  CanLinkCounters counters_;
  CanErrorReport last_error_;
  hal::HalStatus read_status_ = hal::HalStatus::ok;
  double last_attempt_s_ = 0;
  bool attempted_ = false;
  bool opened_here_ = false;  ///< configure() opened the transport (so cleanup() closes it)
  bool bus_off_ = false;
  bool degraded_ = false;
  int consumed_ = 0;
  int holdoff_ = 0;
};

}  // namespace pliant::drivers::socketcan
