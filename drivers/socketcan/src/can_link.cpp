#include "pliant/drivers/socketcan/can_link.hpp"

#include <time.h>

#include <cmath>

namespace pliant::drivers::socketcan {

namespace {

constexpr int kMaxFramesPerRead = 4096;
constexpr int kMaxHoldoff = 1000;
constexpr int kFlushLimit = 4096;

std::int64_t realtime_now_ns() noexcept {
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + static_cast<std::int64_t>(ts.tv_nsec);
}

}  // namespace

double receive_stamp_s(double now_s, std::int64_t realtime_now_ns, std::int64_t rx_realtime_ns, double max_age_s,
                       bool& trusted) noexcept {
  trusted = false;
  if (rx_realtime_ns < 0 || realtime_now_ns < rx_realtime_ns) return now_s;
  const double age_s = static_cast<double>(realtime_now_ns - rx_realtime_ns) * 1e-9;
  if (!(age_s <= max_age_s)) return now_s;
  trusted = true;
  return now_s - age_s;
}

hal::HalStatus validate(const CanLinkConfig& c) noexcept {
  const bool ok = std::isfinite(c.reconnect_interval_s) && c.reconnect_interval_s > 0 && c.max_frames_per_read >= 1 &&
                  c.max_frames_per_read <= kMaxFramesPerRead && std::isfinite(c.max_receive_age_s) &&
                  c.max_receive_age_s > 0 && c.samples_after_restart >= 0 && c.samples_after_restart <= kMaxHoldoff;
  return ok ? hal::HalStatus::ok : hal::HalStatus::invalid_argument;
}

hal::HalStatus CanLink::configure(const CanLinkConfig& config, const std::uint32_t* ids, std::size_t count) noexcept {
  if (validate(config) != hal::HalStatus::ok) return hal::HalStatus::invalid_argument;
  config_ = config;
  counters_ = CanLinkCounters{};
  last_error_ = CanErrorReport{};
  read_status_ = hal::HalStatus::ok;
  bus_off_ = false;
  degraded_ = false;
  holdoff_ = 0;
  consumed_ = 0;
  if (transport_.set_receive_filter(ids, count) != hal::HalStatus::ok) return hal::HalStatus::invalid_argument;
  // A transport the caller opened (e.g. one end of a socketpair) stays as it is and stays
  // open after cleanup; one this link opened is closed again by cleanup.
  if (transport_.is_open()) {
    opened_here_ = false;
    return hal::HalStatus::ok;
  }
  const hal::HalStatus s = transport_.open();
  opened_here_ = s == hal::HalStatus::ok;
  return s;
}

void CanLink::cleanup() noexcept {
  if (opened_here_) transport_.close();
  opened_here_ = false;
}

void CanLink::flush() noexcept {
  // Data frames queued while nobody read are stale; error frames still tell the bus state.
  for (int i = 0; i < kFlushLimit && transport_.is_open(); ++i) {
    CanFrame f;
    CanRxInfo info;
    const CanIo io = transport_.receive(f, info);
    if (io == CanIo::empty) break;
    if (io == CanIo::disconnected) {
      mark_disconnected();
      break;
    }
    if (io == CanIo::ok && is_error_frame(f)) {
      handle_error_frame(f);
    } else if (io == CanIo::ok) {
      ++counters_.flushed_frames;
    } else if (io == CanIo::malformed) {
      ++counters_.malformed_records;
    } else {
      ++counters_.receive_errors;
      break;
    }
  }
  holdoff_ = 0;
}

hal::HalStatus CanLink::begin_read(bool& reopened) noexcept {
  reopened = false;
  consumed_ = 0;
  read_status_ = hal::HalStatus::ok;
  if (transport_.is_open()) return hal::HalStatus::ok;
  const double now = clock_.now_s();
  if (attempted_ && now - last_attempt_s_ < config_.reconnect_interval_s) return hal::HalStatus::disconnected;
  attempted_ = true;
  last_attempt_s_ = now;
  ++counters_.reconnect_attempts;
  if (transport_.open() != hal::HalStatus::ok) return hal::HalStatus::disconnected;
  ++counters_.reconnects;
  reopened = true;
  bus_off_ = false;
  begin_holdoff();
  return hal::HalStatus::ok;
}

void CanLink::mark_disconnected() noexcept {
  transport_.close();
  ++counters_.disconnects;
  // The first reopen attempt comes one interval after the loss, not at once.
  attempted_ = true;
  last_attempt_s_ = clock_.now_s();
  bus_off_ = false;
}

bool CanLink::next_frame(CanFrame& frame, double& stamp_s) noexcept {
  while (consumed_ < config_.max_frames_per_read) {
    CanFrame f;
    CanRxInfo info;
    const CanIo io = transport_.receive(f, info);
    if (io == CanIo::empty) return false;
    ++consumed_;
    if (io == CanIo::malformed) {
      ++counters_.malformed_records;
      continue;
    }
    if (io == CanIo::disconnected) {
      mark_disconnected();
      read_status_ = hal::HalStatus::disconnected;
      return false;
    }
    if (io != CanIo::ok) {
      ++counters_.receive_errors;
      read_status_ = hal::HalStatus::io_error;
      return false;
    }
    if (is_error_frame(f)) {
      handle_error_frame(f);
      continue;
    }
    ++counters_.frames_received;
    const double now = clock_.now_s();
    stamp_s = now;
    if (config_.use_receive_timestamps && info.realtime_ns >= 0) {
      bool trusted = false;
      stamp_s = receive_stamp_s(now, realtime_now_ns(), info.realtime_ns, config_.max_receive_age_s, trusted);
      if (!trusted) ++counters_.untrusted_stamps;
    }
    frame = f;
    return true;
  }
  ++counters_.budget_exhausted;
  return false;
}

void CanLink::handle_error_frame(const CanFrame& frame) noexcept {
  CanErrorReport r;
  if (!decode_can_error(frame, r)) return;
  last_error_ = r;
  ++counters_.error_frames;
  degraded_ = true;
  if (r.rx_overflow()) ++counters_.rx_overflows;
  if ((r.classes & kCanErrNoAck) != 0) ++counters_.no_ack;
  if ((r.classes & kCanErrTxTimeout) != 0) ++counters_.tx_timeouts;
  if (r.bus_off()) {
    if (!bus_off_) ++counters_.bus_off_events;
    bus_off_ = true;
    return;
  }
  if (r.recovered()) {
    const bool was_off = bus_off_;
    if (was_off) ++counters_.bus_restarts;
    bus_off_ = false;
    // Back to error-active from a warning is no restart; a restart or the end of bus-off is.
    if (was_off || (r.classes & kCanErrRestarted) != 0) begin_holdoff();
  }
}

hal::HalStatus CanLink::send(const CanFrame& frame) noexcept {
  const CanIo io = transport_.send(frame);
  switch (io) {
    case CanIo::ok: ++counters_.frames_sent; return hal::HalStatus::ok;
    case CanIo::busy: ++counters_.send_busy; return hal::HalStatus::io_error;
    case CanIo::disconnected:
      ++counters_.send_errors;
      mark_disconnected();
      return hal::HalStatus::disconnected;
    default: ++counters_.send_errors; return hal::HalStatus::io_error;
  }
}

void CanLink::note_sensor_frame() noexcept {
  if (!bus_off_) return;
  bus_off_ = false;
  ++counters_.bus_restarts;
  begin_holdoff();
}

bool CanLink::take_degraded() noexcept {
  const bool d = degraded_;
  degraded_ = false;
  return d;
}

bool CanLink::admit_sample() noexcept {
  if (holdoff_ <= 0) return true;
  --holdoff_;
  ++counters_.held_samples;
  return false;
}

}  // namespace pliant::drivers::socketcan
