// The faults of the wire HIL, each injected where it happens on a real rig: in the Modbus
// server (no answer, an exception answer, a damaged answer, the TCP connection dropped, the
// gripper's fault byte), on the CAN side (bus-off, a storm of error frames, a sensor that stops
// answering, gauges that stop changing, a critical status bit), in the camera (a stalled stamp, a
// repeated frame), and in the clock (its reading jumps ahead).
//
// A case is: inject(rig), clear(rig) after hold_cycles (nullptr: it clears itself), and
// counted(rig), the counter of the stack (driver, stream monitor or guard) that records it.
// Onset: for a fault acted out at the next call (every case but the camera's) the first cycle
// after inject(); a camera fault is scheduled on the mock (hal::FaultEvent) and shows only with
// the next frame, so its onset is the first cycle in which delivered(rig) moves.
#pragma once

#include <cstdint>
#include <vector>

#include "wire_rig.hpp"

namespace pliant::hil {

enum class WireDevice : std::uint8_t { gripper, sensor, camera, clock };

struct WireFault {
  const char* name;
  WireDevice device;
  const char* injected;  ///< what the rig does, for the table
  void (*inject)(WireRig&);
  void (*clear)(WireRig&);                     ///< nullptr: the fault ends by itself
  std::uint64_t (*counted)(const WireRig&);    ///< the stack's count of it: must move
  std::uint64_t (*delivered)(const WireRig&);  ///< camera: the mock's count of faulty frames; else nullptr
  long hold_cycles = 30;                       ///< cycles from inject to clear
};

const char* wire_device_name(WireDevice device) noexcept;

/// Every case, in table order.
std::vector<WireFault> wire_faults();

}  // namespace pliant::hil
