// pliant modbus driver: a Robotiq 2F-85 / 2F-140 gripper as a pliant::hal::Gripper, over Modbus
// RTU (the gripper's own RS-485 link, 115200 8N1, slave 9) or Modbus TCP (a gateway, or the
// emulator in drivers/modbus/emulator). Register map and scaling: robotiq_2f_codec.hpp.
//
// Lifecycle
//   configure  validates the configuration and opens the link (fails when the gripper cannot be
//              reached: disconnected / timeout, or invalid_argument).
//   start      reads the status once (this also settles FC04 versus FC03, below). Then, by
//              `activation`: if_needed - an already activated gripper is used as it is, else the
//              activation sequence begins; always - the sequence always begins; never - nothing
//              is written (the application activates the gripper itself).
//              Activation sequence (Robotiq 2F manual; docs/drivers/modbus.md): write {0,0,0}
//              (reset), wait reset_hold_s on the clock, write rACT = 1, then the gripper reports
//              gSTA = 3. The waits are not spent inside a call: later read() calls advance the
//              sequence. The fingers MOVE during activation (they open and close to calibrate).
//              If gSTA = 3 does not come within activation_timeout_s the sequence starts over
//              (counted in activation_retries). reactivate() restarts it at any time.
//   read       one status transaction -> GripperReading (robotiq_2f_codec.hpp for the mapping);
//              stamp = clock time after the answer; sequence +1 per answered poll. While
//              min_poll_period_s has not passed since the last poll it returns no_data without
//              any I/O. During activation it may also write the activation command.
//   write      move: rPR from width, rSP from speed, rFR from force (bytes, robotiq_2f_codec.hpp),
//                    written as {rACT, rPR, rSP|rFR} then {rACT|rGTO, ...}: clearing rGTO first
//                    makes the gripper take the new goal even after it stopped on an object (the
//                    manual's rule for restarting a stopped axis). When rGTO is already clear
//                    only the second write is made.
//              stop: {rACT, last rPR/rSP/rFR} (rGTO = 0 stops the fingers where they are).
//              open: a move to the widest opening at the given speed with open_force_n.
//              Refused with wrong_state (counted as a rejected write) until the gripper reports
//              activated: a Robotiq ignores motion requests before that. A fault the gripper
//              reports (gFLT) does not refuse writes: the gripper decides, the reading shows it.
//   stop       writes nothing: the gripper keeps executing its last command (call freeze()
//              first to stop the fingers).
//   cleanup    closes the link.
//
// FC04 / FC03: status_read = auto_detect reads with FC04 (current manuals) and, when the gripper
// answers "illegal function", switches to FC03 (2016 manual) for good and repeats the read at
// once (counted in fc03_fallbacks). input_registers / holding_registers force one of them.
//
// Errors: read/write return the link's mapped status (modbus_link.hpp): timeout, disconnected
// (the link reconnects on a later call, at most once per reconnect_interval_s), io_error (CRC,
// malformed answer, Modbus exception). An illegal-function answer to FC03 is io_error.
//
// Bounds: read makes 1 transaction (at most 3 during activation or at the FC03 switch: status,
// fallback status, activation write); write makes at most 2. Each waits at most
// link.response_timeout_s (default 20 ms), so read <= 3 x and write <= 2 x that timeout. No
// allocation, no exceptions after configure.
// Thread safety: drive one instance from one thread.
#pragma once

#include <cstdint>

#include "pliant/drivers/modbus/modbus_link.hpp"
#include "pliant/drivers/modbus/robotiq_2f_codec.hpp"
#include "pliant/hal/clock.hpp"
#include "pliant/hal/gripper.hpp"

namespace pliant::drivers::modbus {

enum class StatusRead : std::uint8_t { auto_detect, input_registers, holding_registers };
enum class ActivationPolicy : std::uint8_t { if_needed, always, never };

struct RobotiqGripperConfig {
  ModbusLinkConfig link;       ///< defaults: RTU /dev/ttyUSB0 115200 8N1, slave 9, 20 ms
  robotiq2f::Scaling scaling;  ///< defaults: 2F-85
  StatusRead status_read = StatusRead::auto_detect;
  ActivationPolicy activation = ActivationPolicy::if_needed;
  double reset_hold_s = 1.0;           ///< wait between the reset and the activation write, >= 0
  double activation_timeout_s = 10.0;  ///< > 0
  double min_poll_period_s = 0.0;      ///< >= 0; 0 polls on every read
  double open_force_n = 100.0;         ///< force limit used by open(), > 0
};

/// Driver counters beyond hal::DeviceCounters and the link's (reset by configure).
struct RobotiqGripperCounters {
  std::uint64_t fc03_fallbacks = 0;      ///< switches from FC04 to FC03 (0 or 1)
  std::uint64_t activations = 0;         ///< activation sequences begun
  std::uint64_t activation_retries = 0;  ///< sequences restarted after activation_timeout_s
  std::uint64_t polls_skipped = 0;       ///< reads answered no_data by min_poll_period_s
};

class RobotiqGripper final : public hal::Gripper {
 public:
  RobotiqGripper(const hal::Clock& clock, const RobotiqGripperConfig& config);

  /// Widths [0, stroke_m], speed up to the model's maximum, forces [min_force_n, max_force_n].
  hal::GripperLimits limits() const noexcept override;

  /// Restarts the activation sequence (the fingers move). wrong_state unless active.
  hal::HalStatus reactivate() noexcept;
  /// True once the gripper reported gACT = 1 and gSTA = 3 (at the last poll).
  bool activated() const noexcept { return robotiq2f::is_activated(last_status_); }
  /// True when status reads use FC03.
  bool using_holding_registers() const noexcept { return table_ == RegisterTable::holding; }
  /// The last status block read (zeros before the first).
  const robotiq2f::Status& last_status() const noexcept { return last_status_; }
  /// The last command block written.
  const robotiq2f::Command& last_command() const noexcept { return last_command_; }
  const RobotiqGripperCounters& driver_counters() const noexcept { return counters_; }
  const ModbusLinkCounters& link_counters() const noexcept { return link_.counters(); }
  const RobotiqGripperConfig& config() const noexcept { return config_; }

 protected:
  hal::HalStatus on_configure() override;
  hal::HalStatus on_start() noexcept override;
  hal::HalStatus on_cleanup() noexcept override;
  hal::HalStatus on_read(hal::GripperReading& out) noexcept override;
  hal::HalStatus on_write(const hal::GripperCommand& command) noexcept override;

 private:
  enum class Phase : std::uint8_t { idle, reset_sent, activate_sent };

  hal::HalStatus poll_status(robotiq2f::Status& out) noexcept;
  hal::HalStatus send(const robotiq2f::Command& command) noexcept;
  hal::HalStatus begin_activation(double now_s) noexcept;
  hal::HalStatus advance_activation(double now_s) noexcept;

  const hal::Clock& clock_;
  RobotiqGripperConfig config_;
  ModbusLink link_;
  RegisterTable table_ = RegisterTable::input;
  bool table_settled_ = false;
  Phase phase_ = Phase::idle;
  double phase_since_s_ = 0;
  bool polled_ = false;
  double last_poll_s_ = 0;
  std::uint64_t sequence_ = 0;
  robotiq2f::Status last_status_;
  robotiq2f::Command last_command_;
  RobotiqGripperCounters counters_;
};

}  // namespace pliant::drivers::modbus
