// pliant drivers/modbus: its device factories in a hal::DeviceRegistry (hal/device_registry.hpp).
//
// Force/torque sensor (RobotiqFt300, docs/drivers/modbus.md):
//   ft300-rtu:DEV       FT 300 on a serial port, stream mode (about 100 Hz, reads never wait)
//   ft300-tcp:HOST      FT 300 behind a Modbus TCP gateway, polled at most every 5 ms
//                       parameters: slave (0..247, default 9), port (tcp: 1..65535, default 502),
//                       tare (the first sample after start is the zero; default false)
// Gripper (RobotiqGripper, Robotiq 2F-85/140):
//   robotiq-rtu:DEV     on a serial port             } polled at most every 10 ms; activation
//   robotiq-tcp:HOST    through Modbus TCP           } policy `never`: an opened gripper is only
//                                                      read and commanded, never activated here
//                       parameters: slave, port (tcp), stroke_m (the opening at full stroke:
//                       0.085 for a 2F-85 (default), 0.140 for a 2F-140)
// HOST is a dotted IPv4 address (no name lookup). Errors: the device's configure status with
// the link's errno in words ("Connection refused"; libmodbus's own codes as "Modbus error N").
// The opened device's info(): the driver and Modbus link counters.
// Host code (allocates, throws on a duplicate registration).
#pragma once

#include "pliant/hal/device_registry.hpp"

namespace pliant::drivers {

/// Registers ft300-rtu, ft300-tcp, robotiq-rtu and robotiq-tcp.
void register_modbus_devices(hal::DeviceRegistry& registry);

}  // namespace pliant::drivers
