// Test helpers for the socketcan driver: a device and its emulator joined by a socketpair (or
// by a named listener, for reconnects), stepped on a manual clock. One cycle = advance the
// clock, read the device once, let the emulator answer what it received.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>

#include "pliant/drivers/socketcan/ati_netcanoem_sensor.hpp"
#include "pliant/drivers/socketcan/emulator/ati_netcanoem_emulator.hpp"
#include "pliant/drivers/socketcan/emulator/robotous_rft_emulator.hpp"
#include "pliant/drivers/socketcan/robotous_rft_sensor.hpp"
#include "pliant/drivers/socketcan/seqpacket_transport.hpp"
#include "pliant/hal/clock.hpp"

namespace pliant::drivers::socketcan::test {

/// The cycle time: 1/1024 s (about 1 ms), exact in binary, so that stamps 10 + k * kTick and
/// every timeout comparison in the tests are exact.
inline constexpr double kTick = 1.0 / 1024.0;

/// A fresh abstract-namespace address per call (no file to clean up).
inline std::string unique_address(const char* tag) {
  static std::atomic<int> counter{0};
  return std::string("@pliant-socketcan-") + tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
}

/// The hand example's calibration (see socketcan_protocol_test.cpp, AtiCalibration.HandExample):
/// Fx = (2 SG0 + 0.5 SG5) / 1000, Fy = SG1 / 1000, Fz = -1.5 SG2 / 1000,
/// Tx = 4 SG3 / 2000, Ty = SG4 / 2000, Tz = -2 SG5 / 2000, in N and N m.
inline ati::Calibration hand_calibration() {
  ati::Calibration c;
  for (float& v : c.matrix) v = 0;
  c.matrix[0 * 6 + 0] = 2.0f;
  c.matrix[0 * 6 + 5] = 0.5f;
  c.matrix[1 * 6 + 1] = 1.0f;
  c.matrix[2 * 6 + 2] = -1.5f;
  c.matrix[3 * 6 + 3] = 4.0f;
  c.matrix[4 * 6 + 4] = 1.0f;
  c.matrix[5 * 6 + 5] = -2.0f;
  c.counts_per_force = 1000;
  c.counts_per_torque = 2000;
  c.force_unit = 2;   // N
  c.torque_unit = 3;  // N m
  return c;
}

/// SG0..SG5 of the hand example, and the wrench they give with hand_calibration() and no bias.
inline constexpr std::int16_t kHandGauges[6] = {100, -200, 300, 50, -400, 20};
inline constexpr double kHandWrench[6] = {0.21, -0.2, -0.45, 0.1, -0.2, -0.02};

/// Checks a reading against kHandWrench (gtest assertions; include gtest before this header).
inline void expect_hand(const hal::WrenchReading& w) {
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(w.wrench[k], kHandWrench[k], 1e-12) << "axis " << k;
}
inline void expect_no_nan(const hal::WrenchReading& w) {
  for (int k = 0; k < 6; ++k) EXPECT_FALSE(std::isnan(w.wrench[k])) << "axis " << k;
}

struct AtiRig {
  hal::ManualClock clock{10.0};
  SeqpacketCanTransport device_end;
  SeqpacketCanTransport sensor_end;
  AtiEmulatorConfig emulator_config;
  std::unique_ptr<AtiNetCanEmulator> emulator;
  AtiNetCanConfig config;
  std::unique_ptr<AtiNetCanForceTorque> ft;

  AtiRig() {
    emulator_config.calibration = hand_calibration();
    config.calibration_index = 3;
    config.link.use_receive_timestamps = false;  // exact stamps on the manual clock
  }
  /// Joins device and emulator with a socketpair (call before make()).
  bool pair() {
    if (SeqpacketCanTransport::make_pair(device_end, sensor_end) != hal::HalStatus::ok) return false;
    emulator = std::make_unique<AtiNetCanEmulator>(sensor_end, emulator_config);
    emulator->set_gauges(kHandGauges);
    return true;
  }
  hal::HalStatus make() {
    ft = std::make_unique<AtiNetCanForceTorque>(device_end, clock, config);
    const hal::HalStatus s = ft->configure();
    if (s != hal::HalStatus::ok) return s;
    return ft->start();
  }
  hal::HalStatus cycle(hal::WrenchReading& w, double dt = kTick) {
    (void)clock.advance(dt);
    const hal::HalStatus s = ft->read(w);
    emulator->service();
    return s;
  }
  /// Cycles until ready() (at most `limit` cycles). True if ready.
  bool run_setup(int limit = 100) {
    hal::WrenchReading w;
    for (int i = 0; i < limit && !ft->ready(); ++i) (void)cycle(w);
    return ft->ready();
  }
  /// Cycles until a read returns ok (at most `limit`); returns the last status.
  hal::HalStatus next_sample(hal::WrenchReading& w, int limit = 20) {
    hal::HalStatus s = hal::HalStatus::no_data;
    for (int i = 0; i < limit; ++i) {
      s = cycle(w);
      if (s == hal::HalStatus::ok) return s;
    }
    return s;
  }
};

struct RftRig {
  hal::ManualClock clock{10.0};
  SeqpacketCanTransport device_end;
  SeqpacketCanTransport sensor_end;
  RftEmulatorConfig emulator_config;
  std::unique_ptr<RobotousRftEmulator> emulator;
  RobotousRftConfig config;
  std::unique_ptr<RobotousRftForceTorque> ft;

  RftRig() { config.link.use_receive_timestamps = false; }
  bool pair() {
    if (SeqpacketCanTransport::make_pair(device_end, sensor_end) != hal::HalStatus::ok) return false;
    emulator = std::make_unique<RobotousRftEmulator>(sensor_end, emulator_config);
    return true;
  }
  hal::HalStatus make() {
    ft = std::make_unique<RobotousRftForceTorque>(device_end, clock, config);
    const hal::HalStatus s = ft->configure();
    if (s != hal::HalStatus::ok) return s;
    return ft->start();
  }
  /// Advance, read, let the emulator handle commands, then stream `packets` packets.
  hal::HalStatus cycle(hal::WrenchReading& w, int packets = 1, double dt = kTick) {
    (void)clock.advance(dt);
    const hal::HalStatus s = ft->read(w);
    emulator->service();
    emulator->stream(packets);
    return s;
  }
  hal::HalStatus next_sample(hal::WrenchReading& w, int limit = 20) {
    hal::HalStatus s = hal::HalStatus::no_data;
    for (int i = 0; i < limit; ++i) {
      s = cycle(w);
      if (s == hal::HalStatus::ok) return s;
    }
    return s;
  }
};

}  // namespace pliant::drivers::socketcan::test
