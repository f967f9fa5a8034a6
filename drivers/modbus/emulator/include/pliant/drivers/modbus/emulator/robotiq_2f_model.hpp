// pliant modbus emulator: a simulated Robotiq 2F gripper behind the real register map
// (robotiq_2f_codec.hpp). The ModbusEmulator serves it over Modbus; tests and HIL rigs may also
// step it directly.
//
// Behaviour (a model of the manual's description, not of the real firmware's timing):
//   - rACT 0 -> 1 starts activation: gSTA = 1 for activation_time_s of stepped time, then
//     gSTA = 3, gACT = 1 and the fingers stand fully open. rACT = 0 resets (gSTA = 0, no motion).
//   - With gSTA = 3, a command with rGTO = 1 starts a motion when rGTO rises or rPR/rSP/rFR
//     change: the fingers move toward rPR at the speed of rSP (Scaling), gOBJ = 0 while moving.
//     rGTO = 0 stops them where they are.
//   - Object: between the fingers sits an object of width object_width_m (NaN = none) and
//     stiffness object_stiffness_n_per_m (+inf = rigid). Closing past its width squeezes it with
//     force k * (object_width - width). Closing stops when that force reaches the force limit of
//     rFR (Scaling; a rigid object stops the fingers at its width) -> gOBJ = 2, or at rPR first
//     -> gOBJ = 3 (a position-limited squeeze). Opening always reaches rPR -> gOBJ = 3.
//   - Grip force: k * max(0, object_width - width); for a rigid object held after contact, the
//     force limit of rFR.
//   - Another object: set_object_model(object) replaces the spring by an object of the caller's
//     (Robotiq2fObject below, e.g. a simulated soft object in a HIL rig): closing stops where its
//     force reaches the force limit (width_at_force), and the grip force, the current and gOBJ
//     follow its force_n(width). set_object_model(nullptr) goes back to the spring.
//   - Current gCU: moving_current_a while moving plus current_per_newton_a * grip force.
//   - Faults: set_fault(byte) puts `byte` in status byte 2 (gFLT low nibble, kFLT high) and
//     stops the fingers; commands are latched but do not move them while the fault lasts, and
//     after set_fault(0) they stay put until the next motion command. Minor faults follow the
//     manual: rGTO = 1 before activation completes -> gFLT 0x05; rGTO = 1 with rACT = 0 -> 0x07;
//     cleared by the next valid command.
// Widths use the same Scaling as the driver (position byte <-> width), so a driver configured
// with the same Scaling reads back the model's width to within one position byte.
// Not thread-safe (the emulator locks around it). Allocation-free after construction.
#pragma once

#include <cstdint>
#include <limits>

#include "pliant/drivers/modbus/robotiq_2f_codec.hpp"

namespace pliant::drivers::modbus {

struct Robotiq2fModelConfig {
  robotiq2f::Scaling scaling;                                                 ///< 2F-85 by default
  double activation_time_s = 0.5;                                             ///< >= 0
  double object_width_m = std::numeric_limits<double>::quiet_NaN();           ///< NaN: nothing to grasp
  double object_stiffness_n_per_m = std::numeric_limits<double>::infinity();  ///< > 0, +inf rigid
  double current_per_newton_a = 0.003;                                        ///< >= 0
  double moving_current_a = 0.05;                                             ///< >= 0
};

/// An object between the fingers other than the built-in spring. The model calls it from
/// step() and from the status getters; in a ModbusEmulator that is under the emulator's lock, on
/// the server thread as well as the caller's: both members must be safe to call from there
/// (e.g. read only state that is fixed while the emulator runs). noexcept, allocation-free.
class Robotiq2fObject {
 public:
  virtual ~Robotiq2fObject() = default;
  /// Grip force (N, >= 0) with the fingers at width_m; it must not decrease as width_m shrinks.
  virtual double force_n(double width_m) const noexcept = 0;
  /// The widest width at which force_n(width) reaches `force_n`; NaN when it never does inside
  /// the stroke (the fingers then close to their target).
  virtual double width_at_force(double force_n) const noexcept = 0;

 protected:
  Robotiq2fObject() = default;
  Robotiq2fObject(const Robotiq2fObject&) = default;
  Robotiq2fObject& operator=(const Robotiq2fObject&) = default;
};

class Robotiq2fModel {
 public:
  explicit Robotiq2fModel(const Robotiq2fModelConfig& config = {}) noexcept;

  /// Latches a command block (what an FC16 write to 0x03E8 carries).
  void write_command(const robotiq2f::Command& command) noexcept;
  /// Advances the simulation by dt_s (>= 0; negative or NaN is ignored). Exact for any dt_s:
  /// motion is piecewise linear and stops are computed, not sampled.
  void step(double dt_s) noexcept;

  /// The status block the gripper would answer now.
  robotiq2f::Status status() const noexcept;
  void status_registers(std::uint16_t out[robotiq2f::kRegisterCount]) const noexcept;

  double width_m() const noexcept { return width_m_; }
  double grip_force_n() const noexcept;
  double current_a() const noexcept;
  bool moving() const noexcept { return moving_; }
  const robotiq2f::Command& command() const noexcept { return command_; }
  const Robotiq2fModelConfig& config() const noexcept { return config_; }

  /// Replaces the object (width NaN removes it; stiffness > 0, +inf rigid).
  void set_object(double width_m, double stiffness_n_per_m) noexcept;
  /// Squeezes `object` instead of the spring from now on (nullptr: the spring again). The
  /// object must outlive its use here.
  void set_object_model(const Robotiq2fObject* object) noexcept { object_ = object; }
  /// Fault byte (0 clears): see the top of the file.
  void set_fault(std::uint8_t fault_byte) noexcept;
  /// Puts the fingers at width_m (clamped to the stroke) and stops them: test set-up.
  void set_width(double width_m) noexcept;

 private:
  bool has_object() const noexcept;
  double contact_stop_width() const noexcept;

  Robotiq2fModelConfig config_;
  const Robotiq2fObject* object_ = nullptr;  ///< replaces the spring when set
  robotiq2f::Command command_;
  double width_m_ = 0;
  std::uint8_t gsta_ = robotiq2f::kStaReset;
  std::uint8_t gobj_ = robotiq2f::kObjMoving;
  std::uint8_t fault_ = 0;
  std::uint8_t minor_fault_ = 0;
  bool moving_ = false;
  double activation_elapsed_s_ = 0;
};

}  // namespace pliant::drivers::modbus
