#include "pliant/drivers/socketcan/robotous_rft_sensor.hpp"

#include <cmath>

namespace pliant::drivers::socketcan {

using hal::HalStatus;

namespace {

constexpr std::uint8_t kPendingRate = 1;
constexpr std::uint8_t kPendingBias = 2;
constexpr std::uint8_t kPendingStream = 4;

bool finite_pos(double v) { return std::isfinite(v) && v > 0; }

}  // namespace

RobotousRftForceTorque::RobotousRftForceTorque(CanTransport& transport, const hal::Clock& clock,
                                               const RobotousRftConfig& config) noexcept
    : clock_(clock), config_(config), link_(transport, clock) {}

HalStatus RobotousRftForceTorque::on_configure() {
  const RobotousRftConfig& c = config_;
  if (!rft::valid(c.ids) || !finite_pos(c.force_divider) || !finite_pos(c.torque_divider) || !finite_pos(c.timeout_s) ||
      c.output_rate_code < -1 || c.output_rate_code > rft::kMaxOutputRateCode) {
    return HalStatus::invalid_argument;
  }
  const std::uint32_t ids[2] = {c.ids.response_1, c.ids.response_2};
  const HalStatus s = link_.configure(c.link, ids, 2);
  if (s != HalStatus::ok) return s;
  counters_ = RftCounters{};
  last_packet_ = rft::FtPacket{};
  last_overload_ = 0;
  sequence_ = 0;
  return HalStatus::ok;
}

HalStatus RobotousRftForceTorque::on_start() noexcept {
  link_.flush();
  assembler_.reset();
  const double now = clock_.now_s();
  pending_ = static_cast<std::uint8_t>(kPendingStream | (config_.output_rate_code >= 0 ? kPendingRate : 0) |
                                       (config_.bias_on_start ? kPendingBias : 0));
  stream_requested_ = false;
  requested_s_ = now;
  last_sample_s_ = now;
  return HalStatus::ok;
}

HalStatus RobotousRftForceTorque::on_stop() noexcept {
  pending_ = 0;
  stream_requested_ = false;
  assembler_.reset();
  // Best effort: a sensor left streaming only costs bus load, and the link may be down.
  (void)send_command(rft::kCmdFtStop, 0);
  return HalStatus::ok;
}

HalStatus RobotousRftForceTorque::on_cleanup() noexcept {
  link_.cleanup();
  return HalStatus::ok;
}

HalStatus RobotousRftForceTorque::send_command(std::uint8_t code, std::uint8_t arg) noexcept {
  const HalStatus s = link_.send(rft::make_command(config_.ids, code, arg));
  if (s == HalStatus::ok) {
    ++counters_.commands_sent;
  } else {
    ++counters_.send_failures;
  }
  return s;
}

HalStatus RobotousRftForceTorque::tare() noexcept {
  if (state() != hal::LifecycleState::active) return HalStatus::wrong_state;
  return send_command(rft::kCmdSetBias, 1);
}

HalStatus RobotousRftForceTorque::clear_tare() noexcept {
  if (state() != hal::LifecycleState::active) return HalStatus::wrong_state;
  return send_command(rft::kCmdSetBias, 0);
}

void RobotousRftForceTorque::send_pending(double now) noexcept {
  // In protocol order: the rate first, then the bias, then the stream; a command that could
  // not be sent stays pending for the next read.
  if ((pending_ & kPendingRate) != 0 &&
      send_command(rft::kCmdSetOutputRate, static_cast<std::uint8_t>(config_.output_rate_code)) == HalStatus::ok) {
    pending_ = static_cast<std::uint8_t>(pending_ & ~kPendingRate);
  }
  if ((pending_ & kPendingBias) != 0 && send_command(rft::kCmdSetBias, 1) == HalStatus::ok) {
    pending_ = static_cast<std::uint8_t>(pending_ & ~kPendingBias);
  }
  if ((pending_ & kPendingStream) != 0 && send_command(rft::kCmdFtStart, 0) == HalStatus::ok) {
    pending_ = static_cast<std::uint8_t>(pending_ & ~kPendingStream);
    ++counters_.stream_requests;
    stream_requested_ = true;
    requested_s_ = now;
  }
}

void RobotousRftForceTorque::handle_frame(const CanFrame& frame, double stamp_s, double now, hal::WrenchReading& sample,
                                          bool& have) noexcept {
  const rft::FrameRole role = rft::classify(frame, config_.ids);
  if (role == rft::FrameRole::foreign) {
    ++counters_.foreign_frames;
    return;
  }
  if (role == rft::FrameRole::wrong_dlc) {
    ++counters_.wrong_dlc;
    return;
  }
  link_.note_sensor_frame();
  switch (assembler_.add(role, frame)) {
    case rft::PacketAssembler::Result::partial:
    case rft::PacketAssembler::Result::ignored: return;
    case rft::PacketAssembler::Result::replaced_first:
    case rft::PacketAssembler::Result::orphan_second: ++counters_.incomplete_packets; return;
    case rft::PacketAssembler::Result::complete: break;
  }
  rft::FtPacket p;
  if (rft::decode_ft_packet(assembler_.packet(), p) != rft::PacketError::none) {
    ++counters_.other_responses;
    return;
  }
  ++counters_.complete_packets;
  if (p.overload != 0) ++counters_.overload_packets;
  last_sample_s_ = now;
  if (!link_.admit_sample()) return;
  ++sequence_;
  rft::raw_to_wrench(p.raw, config_.force_divider, config_.torque_divider, sample.wrench);
  sample.header.stamp_s = stamp_s;
  sample.header.sequence = sequence_;
  sample.header.status_bits = p.overload != 0 ? (hal::kFtAdcHigh | hal::kFtAnyError) : 0u;
  last_packet_ = p;
  last_overload_ = p.overload;
  have = true;
}

HalStatus RobotousRftForceTorque::on_read(hal::WrenchReading& out) noexcept {
  bool reopened = false;
  const HalStatus link = link_.begin_read(reopened);
  if (link != HalStatus::ok) return link;
  double now = clock_.now_s();
  if (reopened) {
    // Ask for the stream again (the sensor may have rebooted); never re-bias on a reconnect.
    assembler_.reset();
    pending_ = static_cast<std::uint8_t>(kPendingStream | (config_.output_rate_code >= 0 ? kPendingRate : 0));
    stream_requested_ = false;
    requested_s_ = now;
    last_sample_s_ = now;
  }
  hal::WrenchReading sample;
  bool have = false;
  CanFrame frame;
  double stamp_s = 0;
  while (link_.next_frame(frame, stamp_s)) handle_frame(frame, stamp_s, now, sample, have);
  const HalStatus rx = link_.read_status();
  if (rx != HalStatus::ok && !have) return rx;
  if (link_.bus_off()) return HalStatus::bus_off;
  now = clock_.now_s();
  const bool stale = now - last_sample_s_ > config_.timeout_s;
  if (rx == HalStatus::ok) {
    // A stream that went quiet is requested again, once per timeout_s.
    if (stale && stream_requested_ && now - requested_s_ >= config_.timeout_s) pending_ |= kPendingStream;
    if (pending_ != 0) send_pending(now);
  }
  if (have) {
    if (link_.take_degraded()) sample.header.status_bits |= hal::kFtCanBusError;
    out = sample;
    return HalStatus::ok;
  }
  return stale ? HalStatus::timeout : HalStatus::no_data;
}

}  // namespace pliant::drivers::socketcan
