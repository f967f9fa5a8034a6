#include "pliant/drivers/socketcan/ati_netcanoem_sensor.hpp"

#include <cmath>
#include <cstring>

namespace pliant::drivers::socketcan {

using hal::HalStatus;

namespace {

// Every opcode that has a response (RESET, 0xC, has none; 0xA and 0xB are unused).
constexpr std::uint8_t kResponseOpcodes[] = {0x0, 0x1, 0x2, 0x3, 0x4, 0x5, 0x6, 0x7, 0x8, 0x9, 0xd, 0xe, 0xf};

bool finite_nonneg(double v) { return std::isfinite(v) && v >= 0; }
bool finite_pos(double v) { return std::isfinite(v) && v > 0; }

}  // namespace

AtiNetCanForceTorque::AtiNetCanForceTorque(CanTransport& transport, const hal::Clock& clock,
                                           const AtiNetCanConfig& config) noexcept
    : clock_(clock), config_(config), link_(transport, clock) {}

HalStatus AtiNetCanForceTorque::on_configure() {
  const AtiNetCanConfig& c = config_;
  if (!ati::valid_base_id(c.base_id) || c.calibration_index >= ati::kCalibrationCount ||
      !finite_nonneg(c.poll_period_s) || !finite_pos(c.response_timeout_s) || !finite_pos(c.timeout_s) ||
      c.tare_samples_on_start < 0 || c.tare_samples_on_start > kMaxTareSamples) {
    return HalStatus::invalid_argument;
  }
  for (double b : c.gauge_bias) {
    if (!std::isfinite(b)) return HalStatus::invalid_argument;
  }
  if (!c.calibration_from_device && ati::make_scaling(c.calibration, scaling_) != ati::CalibrationError::none) {
    return HalStatus::invalid_argument;
  }
  std::uint32_t ids[sizeof kResponseOpcodes];
  for (std::size_t i = 0; i < sizeof kResponseOpcodes; ++i) {
    ids[i] = ati::can_id(c.base_id, static_cast<ati::Opcode>(kResponseOpcodes[i]));
  }
  const HalStatus s = link_.configure(c.link, ids, sizeof kResponseOpcodes);
  if (s != HalStatus::ok) return s;
  counters_ = AtiCounters{};
  info_ = AtiDeviceInfo{};
  last_gauges_ = ati::GaugeSample{};
  sequence_ = 0;
  std::memcpy(bias_, c.gauge_bias, sizeof bias_);
  tare_target_ = 0;
  tare_blocks_ = false;
  return HalStatus::ok;
}

HalStatus AtiNetCanForceTorque::on_start() noexcept {
  link_.flush();
  const double now = clock_.now_s();
  restart_setup(now);
  last_sample_s_ = now;
  tare_after_setup_ = true;
  return HalStatus::ok;
}

HalStatus AtiNetCanForceTorque::on_stop() noexcept {
  poll_outstanding_ = false;
  assembler_.reset();
  return HalStatus::ok;
}

HalStatus AtiNetCanForceTorque::on_cleanup() noexcept {
  link_.cleanup();
  return HalStatus::ok;
}

HalStatus AtiNetCanForceTorque::tare(int samples) noexcept {
  if (state() == hal::LifecycleState::unconfigured) return HalStatus::wrong_state;
  if (samples < 1 || samples > kMaxTareSamples) return HalStatus::invalid_argument;
  tare_target_ = samples;
  tare_count_ = 0;
  for (double& s : tare_sum_) s = 0;
  tare_blocks_ = false;
  return HalStatus::ok;
}

HalStatus AtiNetCanForceTorque::set_gauge_bias(const double bias[6]) noexcept {
  for (int k = 0; k < 6; ++k) {
    if (!std::isfinite(bias[k])) return HalStatus::invalid_argument;
  }
  std::memcpy(bias_, bias, sizeof bias_);
  tare_target_ = 0;
  tare_blocks_ = false;
  return HalStatus::ok;
}

void AtiNetCanForceTorque::restart_setup(double now) noexcept {
  phase_ = Phase::setup;
  step_ = Step::set_calibration;
  step_sent_ = false;
  step_sent_s_ = now;
  matrix_row_ = 0;
  matrix_parts_ = 0;
  setup_error_ = AtiSetupError::none;
  calibration_error_ = ati::CalibrationError::none;
  poll_outstanding_ = false;
  polled_once_ = false;
  assembler_.reset();
}

bool AtiNetCanForceTorque::send_request(ati::Opcode op, std::uint8_t arg) noexcept {
  if (link_.send(ati::make_request(config_.base_id, op, arg)) == HalStatus::ok) return true;
  ++counters_.send_failures;
  return false;
}

void AtiNetCanForceTorque::send_step(double now) noexcept {
  bool sent = false;
  switch (step_) {
    case Step::set_calibration: sent = send_request(ati::Opcode::set_calibration, config_.calibration_index); break;
    case Step::read_matrix:
      matrix_parts_ = 0;
      sent = send_request(ati::Opcode::read_matrix, static_cast<std::uint8_t>(matrix_row_));
      break;
    case Step::read_counts: sent = send_request(ati::Opcode::read_counts, 0); break;
    case Step::read_units: sent = send_request(ati::Opcode::read_units, 0); break;
    case Step::read_serial: sent = send_request(ati::Opcode::read_serial, 0); break;
    case Step::read_firmware: sent = send_request(ati::Opcode::read_firmware, 0); break;
    case Step::done: return;
  }
  step_sent_ = sent;
  if (sent) {
    step_sent_s_ = now;
    ++counters_.setup_requests;
  }
}

void AtiNetCanForceTorque::drive_setup(double now) noexcept {
  if (step_ == Step::done) return;
  if (!step_sent_) {
    send_step(now);
  } else if (now - step_sent_s_ >= config_.response_timeout_s) {
    ++counters_.setup_retries;
    send_step(now);
  }
}

void AtiNetCanForceTorque::advance_setup(double now) noexcept {
  // One step answered: the sensor is alive, so the stale timer restarts.
  last_sample_s_ = now;
  step_sent_ = false;
  switch (step_) {
    case Step::set_calibration:
      step_ = config_.calibration_from_device ? Step::read_matrix : Step::read_serial;
      matrix_row_ = 0;
      break;
    case Step::read_matrix:
      if (++matrix_row_ < 6) return;  // same step, next row
      step_ = Step::read_counts;
      break;
    case Step::read_counts: step_ = Step::read_units; break;
    case Step::read_units: {
      const ati::CalibrationError e = ati::make_scaling(info_.calibration, scaling_);
      if (e != ati::CalibrationError::none) {
        calibration_error_ = e;
        fail_setup(AtiSetupError::bad_calibration, now);
        return;
      }
      step_ = Step::read_serial;
      break;
    }
    case Step::read_serial: step_ = Step::read_firmware; break;
    case Step::read_firmware: finish_setup(now); break;
    case Step::done: break;
  }
}

void AtiNetCanForceTorque::finish_setup(double now) noexcept {
  step_ = Step::done;
  if (!config_.calibration_from_device) info_.calibration = config_.calibration;  // scaling_ made at configure
  phase_ = Phase::polling;
  ++counters_.setups_completed;
  poll_outstanding_ = false;
  polled_once_ = false;
  last_sample_s_ = now;
  // Tare only after start's setup: after a reconnect the gripper may hold a load, and
  // re-zeroing would hide it.
  if (tare_after_setup_ && config_.tare_samples_on_start > 0) {
    (void)tare(config_.tare_samples_on_start);
    tare_blocks_ = true;
  }
  tare_after_setup_ = false;
}

void AtiNetCanForceTorque::fail_setup(AtiSetupError e, double now) noexcept {
  phase_ = Phase::failed;
  setup_error_ = e;
  failed_at_s_ = now;
  step_sent_ = false;
  ++counters_.setup_failures;
}

void AtiNetCanForceTorque::handle_setup_response(const ati::Response& r, double now) noexcept {
  // Only the answer to the step in flight counts; anything else is dropped as unexpected.
  switch (step_) {
    case Step::set_calibration:
      if (r.opcode != ati::Opcode::set_calibration) break;
      if (r.byte != config_.calibration_index) {
        fail_setup(AtiSetupError::calibration_refused, now);
      } else {
        advance_setup(now);
      }
      return;
    case Step::read_matrix: {
      const auto part = static_cast<int>(r.opcode) - static_cast<int>(ati::Opcode::read_matrix);
      if (part < 0 || part > 2) break;
      float* row = info_.calibration.matrix + 6 * matrix_row_;
      row[2 * part] = r.matrix[0];
      row[2 * part + 1] = r.matrix[1];
      matrix_parts_ = static_cast<std::uint8_t>(matrix_parts_ | (1u << part));
      if (matrix_parts_ == 7) advance_setup(now);
      return;
    }
    case Step::read_counts:
      if (r.opcode != ati::Opcode::read_counts) break;
      info_.calibration.counts_per_force = r.counts_per_force;
      info_.calibration.counts_per_torque = r.counts_per_torque;
      advance_setup(now);
      return;
    case Step::read_units:
      if (r.opcode != ati::Opcode::read_units) break;
      info_.calibration.force_unit = r.force_unit;
      info_.calibration.torque_unit = r.torque_unit;
      advance_setup(now);
      return;
    case Step::read_serial:
      if (r.opcode != ati::Opcode::read_serial) break;
      std::memcpy(info_.serial, r.serial, 8);
      info_.serial[8] = '\0';
      advance_setup(now);
      return;
    case Step::read_firmware:
      if (r.opcode != ati::Opcode::read_firmware) break;
      info_.firmware_major = r.firmware_major;
      info_.firmware_minor = r.firmware_minor;
      info_.firmware_build = r.firmware_build;
      advance_setup(now);
      return;
    case Step::done: break;
  }
  ++counters_.unexpected_frames;
}

void AtiNetCanForceTorque::on_gauges(const ati::GaugeSample& g, double stamp_s, hal::WrenchReading& sample,
                                     bool& have) noexcept {
  if (tare_target_ > 0 && g.status == 0) {
    for (int k = 0; k < 6; ++k) tare_sum_[k] += static_cast<double>(g.gauges[k]);
    if (++tare_count_ >= tare_target_) {
      for (int k = 0; k < 6; ++k) bias_[k] = tare_sum_[k] / static_cast<double>(tare_count_);
      tare_target_ = 0;
      tare_blocks_ = false;
      ++counters_.tares_completed;
    }
  }
  if (tare_blocks_) return;
  if (!link_.admit_sample()) return;
  ++sequence_;
  ati::gauges_to_wrench(scaling_, g.gauges, bias_, sample.wrench);
  sample.header.stamp_s = stamp_s;
  sample.header.sequence = sequence_;
  sample.header.status_bits = g.status;
  last_gauges_ = g;
  have = true;
}

void AtiNetCanForceTorque::handle_frame(const CanFrame& frame, double stamp_s, double now, hal::WrenchReading& sample,
                                        bool& have) noexcept {
  ati::Response r;
  switch (ati::decode_response(frame, config_.base_id, r)) {
    case ati::DecodeError::none: break;
    case ati::DecodeError::foreign_id: ++counters_.foreign_frames; return;
    case ati::DecodeError::unknown_opcode: ++counters_.unknown_opcodes; return;
    case ati::DecodeError::wrong_dlc: ++counters_.wrong_dlc; return;
  }
  link_.note_sensor_frame();
  if (r.opcode == ati::Opcode::read_gauges || r.opcode == ati::Opcode::gauges_second) {
    if (phase_ != Phase::polling || !poll_outstanding_) {
      ++counters_.unexpected_frames;  // late (after a response timeout) or unsolicited
      return;
    }
    switch (assembler_.add(r)) {
      case ati::GaugeAssembler::Result::complete:
        poll_outstanding_ = false;
        ++counters_.complete_samples;
        last_sample_s_ = now;
        on_gauges(assembler_.sample(), stamp_s, sample, have);
        break;
      case ati::GaugeAssembler::Result::replaced: ++counters_.incomplete_samples; break;
      case ati::GaugeAssembler::Result::partial:
      case ati::GaugeAssembler::Result::ignored: break;
    }
    return;
  }
  if (phase_ == Phase::setup && step_sent_) {
    handle_setup_response(r, now);
  } else {
    ++counters_.unexpected_frames;
  }
}

void AtiNetCanForceTorque::drive_polling(double now) noexcept {
  if (poll_outstanding_ && now - poll_sent_s_ >= config_.response_timeout_s) {
    ++counters_.unanswered_polls;
    if (assembler_.reset()) ++counters_.incomplete_samples;
    poll_outstanding_ = false;
  }
  if (poll_outstanding_ || link_.bus_off()) return;
  if (polled_once_ && now - poll_sent_s_ < config_.poll_period_s) return;
  // A half left over from an abandoned poll must not pair with this poll's answer.
  if (assembler_.reset()) ++counters_.incomplete_samples;
  if (!send_request(ati::Opcode::read_gauges, 0)) return;
  ++counters_.polls_sent;
  poll_outstanding_ = true;
  polled_once_ = true;
  poll_sent_s_ = now;
}

HalStatus AtiNetCanForceTorque::on_read(hal::WrenchReading& out) noexcept {
  bool reopened = false;
  const HalStatus link = link_.begin_read(reopened);
  if (link != HalStatus::ok) return link;
  double now = clock_.now_s();
  if (reopened) {
    // The sensor may have been power-cycled while the link was down: set it up again.
    restart_setup(now);
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
  if (rx == HalStatus::ok) {
    if (phase_ == Phase::failed && now - failed_at_s_ >= config_.link.reconnect_interval_s) restart_setup(now);
    if (phase_ == Phase::setup) drive_setup(now);
    if (phase_ == Phase::polling) drive_polling(now);
  }
  if (have) {
    if (link_.take_degraded()) sample.header.status_bits |= hal::kFtCanBusError;
    out = sample;
    return HalStatus::ok;
  }
  if (phase_ == Phase::failed) return HalStatus::device_fault;
  if (now - last_sample_s_ > config_.timeout_s) return HalStatus::timeout;
  return HalStatus::no_data;
}

}  // namespace pliant::drivers::socketcan
