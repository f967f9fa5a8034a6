// pliant modbus emulator: a Modbus server (libmodbus's server API) that answers like a Robotiq
// 2F gripper and a Robotiq FT 300 on one slave ID, with fault injection. For the driver tests
// and for hardware-in-the-loop rigs that want the real protocol without the hardware.
//
// Transports
//   tcp      listens on 127.0.0.1:port (port 0: the kernel picks a free one; port() tells which).
//            Up to 8 clients at a time (a gripper and a sensor driver may share one emulator);
//            further connections are closed at once and counted as refused.
//   rtu_pty  creates a pseudo-terminal pair and serves Modbus RTU on its master side;
//            device_path() is the slave side to give the driver as its serial device (any baud).
//
// Register map (slave slave_id, default 9; requests for other IDs get no answer)
//   holding 180..185    FT 300 Fx Fy Fz Mx My Mz (int16; /100 N, /1000 N m) from set_wrench(),
//                       plus the simulated grip force on ft_grip_force_axis when that is 0..5
//   holding 410         FT 300 stream control (writes are recorded; the binary stream itself is
//                       a serial feature and is not emulated)
//   holding 1000..1002  Robotiq command block (0x03E8): an FC16/FC06 write goes to the model
//   input   2000..2002  Robotiq status block (0x07D0) for FC04, and the same at holding
//                       2000..2002 for FC03
// Every request first brings the registers up to date with the model. Unknown addresses get the
// standard "illegal data address" exception (modbus_reply).
//
// Time: the model moves only when time passes. By default only advance(dt_s) moves it (stepped
// tests and HIL loops on a ManualClock, reproducible); with real_time = true every request also
// advances it by the steady-clock time since the previous request.
//
// Fault injection (each takes effect on the next request(s)):
//   drop_replies(n)          the next n requests get no answer (the client times out)
//   corrupt_replies(n)       the next n answers are damaged: TCP - wrong transaction ID;
//                            RTU - wrong CRC (the client sees a bad response). Writes still act.
//   set_fc04_supported(f)    false: FC04 is answered with exception 1 "illegal function"
//   disconnect_clients()     TCP: shuts every current connection down (clients see them drop)
//   set_refuse_connections   TCP: accept and close new connections at once
//   set_gripper_fault(byte)  the gripper's status byte 2 (gFLT | kFLT << 4); fingers freeze
// Thread safety: every public member may be called from any thread while the server thread
// runs; they lock one mutex (so a call waits at most for one request being answered). One
// thread serves all clients: a client that stops in the middle of a request holds the others
// up to libmodbus's byte timeout (0.5 s).
// Not real-time code: it allocates in start() and logs nothing.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "pliant/drivers/modbus/emulator/robotiq_2f_model.hpp"
#include "pliant/drivers/modbus/robotiq_2f_codec.hpp"

namespace pliant::drivers::modbus {

enum class EmulatorTransport : std::uint8_t { tcp, rtu_pty };

struct ModbusEmulatorConfig {
  EmulatorTransport transport = EmulatorTransport::tcp;
  std::uint16_t port = 0;        ///< tcp; 0 = any free port
  int slave_id = 9;              ///< 1..247
  Robotiq2fModelConfig gripper;  ///< model, object and scaling
  bool real_time = false;        ///< see "Time" above
  int ft_grip_force_axis = -1;   ///< -1: none; 0..5: add the grip force (N) to this wrench axis
};

struct ModbusEmulatorCounters {
  std::uint64_t requests = 0;         ///< requests received for our slave ID
  std::uint64_t replies = 0;          ///< normal answers sent (exceptions included)
  std::uint64_t exceptions = 0;       ///< exception answers (illegal function injected or address)
  std::uint64_t dropped = 0;          ///< requests left unanswered by drop_replies
  std::uint64_t corrupted = 0;        ///< answers damaged by corrupt_replies
  std::uint64_t other_slave = 0;      ///< requests for another slave ID (no answer)
  std::uint64_t bad_requests = 0;     ///< receive errors (malformed request, CRC)
  std::uint64_t connections = 0;      ///< TCP connections accepted and served
  std::uint64_t refused = 0;          ///< TCP connections closed at once (refusing, or 8 already)
  std::uint64_t disconnects = 0;      ///< TCP connections that ended (either side)
  std::uint64_t command_writes = 0;   ///< writes that reached the gripper command block
  std::uint64_t stream_requests = 0;  ///< writes of 0x0200 to register 410
};

/// A snapshot of the simulated gripper.
struct EmulatedGripperState {
  double width_m = 0;
  double grip_force_n = 0;
  bool moving = false;
  robotiq2f::Status status;
  robotiq2f::Command command;
};

class ModbusEmulator {
 public:
  explicit ModbusEmulator(const ModbusEmulatorConfig& config = {});
  ~ModbusEmulator();  ///< stops the server
  ModbusEmulator(const ModbusEmulator&) = delete;
  ModbusEmulator& operator=(const ModbusEmulator&) = delete;

  /// Opens the transport and starts the server thread. False (with a reason in *error when
  /// given) if it could not; calling it twice is an error.
  bool start(std::string* error = nullptr);
  /// Stops the thread and closes everything. Idempotent.
  void stop();

  std::uint16_t port() const;       ///< tcp: the bound port (after start)
  std::string device_path() const;  ///< rtu_pty: the slave side of the pseudo-terminal

  // Simulation.
  void advance(double dt_s);
  void set_object(double width_m, double stiffness_n_per_m);
  /// The gripper squeezes `object` instead of its spring (Robotiq2fModel::set_object_model;
  /// nullptr: the spring). Its members are called under the emulator's lock, from the server
  /// thread too; it must outlive the emulator's use of it (clear it or stop() first).
  void set_object_model(const Robotiq2fObject* object);
  void set_gripper_width(double width_m);
  void set_gripper_fault(std::uint8_t fault_byte);
  void set_wrench(const double wrench[6]);
  EmulatedGripperState gripper() const;
  /// A holding register as the server holds it now (0 outside the map).
  std::uint16_t holding_register(int address) const;

  // Fault injection.
  void drop_replies(unsigned count);
  void corrupt_replies(unsigned count);
  void set_fc04_supported(bool supported);
  /// TCP only: false when no client is connected.
  bool disconnect_clients();
  void set_refuse_connections(bool refuse);

  ModbusEmulatorCounters counters() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pliant::drivers::modbus
