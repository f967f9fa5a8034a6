// pliant drivers/socketcan: its device factories in a hal::DeviceRegistry (hal/device_registry.hpp).
//
// Force/torque sensors on a raw AF_CAN socket (RawCanTransport; docs/drivers/socketcan.md):
//   ati-can:IFACE       ATI F/T with the NETCANOEM board     parameters: base_id (required, 0..0x7f),
//                                                             tare (100 samples at start; default false)
//   robotous-can:IFACE  Robotous RFT                         parameters: command_id (required, 0..0x7ff),
//                                                             response_1 (0x01), response_2 (0x02),
//                                                             tare (the sensor's bias at start)
// IFACE is a network interface name of 1..15 characters; integers are decimal or 0x-hexadecimal.
// Errors: the sensor's configure status with the reason in words (no SocketCAN in the kernel, no
// such interface and how to bring it up, else the socket's errno). The opened device's info():
// the protocol and CAN link counters (ATI: serial number and firmware too).
// Host code (allocates, throws on a duplicate registration).
#pragma once

#include "pliant/hal/device_registry.hpp"

namespace pliant::drivers {

/// Registers ati-can and robotous-can.
void register_socketcan_devices(hal::DeviceRegistry& registry);

}  // namespace pliant::drivers
