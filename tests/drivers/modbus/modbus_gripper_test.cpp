// RobotiqGripper against the emulator over real Modbus TCP (127.0.0.1, a free port) and Modbus
// RTU (a pseudo-terminal): the activation sequence, moves, object detection, fault decoding, the
// FC04 -> FC03 fallback, timeouts, damaged answers, disconnection and reconnection with their
// counters. Devices run on a ManualClock; the emulator's fingers move only when the test
// advances them, so nothing here depends on the speed of the machine.
#include <gtest/gtest.h>
#include <modbus.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "pliant/drivers/modbus/emulator/modbus_emulator.hpp"
#include "pliant/drivers/modbus/robotiq_gripper.hpp"
#include "pliant/hal/guard_inputs.hpp"

namespace pliant::drivers::modbus {
namespace {

using hal::HalStatus;
namespace r2f = robotiq2f;

constexpr double kAnswerBudgetS = 2.0;  // generous: only injected silences ever use it up
constexpr double kByteWidthM = 0.085 / 255.0;
constexpr double kPastReconnectS = 0.15;  // more than reconnect_interval_s (0.1), clear of rounding

void tick(hal::ManualClock& clock, double dt_s) { ASSERT_EQ(clock.advance(dt_s), HalStatus::ok); }

ModbusEmulatorConfig emulator_config(EmulatorTransport transport = EmulatorTransport::tcp) {
  ModbusEmulatorConfig c;
  c.transport = transport;
  c.gripper.activation_time_s = 0.5;
  return c;
}

RobotiqGripperConfig tcp_config(std::uint16_t port) {
  RobotiqGripperConfig c;
  c.link.transport = ModbusTransport::tcp;
  c.link.host = "127.0.0.1";
  c.link.port = port;
  c.link.response_timeout_s = kAnswerBudgetS;
  c.link.reconnect_interval_s = 0.1;
  c.reset_hold_s = 0.2;
  return c;
}

class RobotiqGripperTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string error;
    ASSERT_TRUE(emulator.start(&error)) << error;
    config = tcp_config(emulator.port());
  }

  void make() { gripper = std::make_unique<RobotiqGripper>(clock, config); }

  // configure + start + the whole activation sequence, checked step by step.
  void activate() {
    make();
    ASSERT_EQ(gripper->configure(), HalStatus::ok);
    ASSERT_EQ(gripper->start(), HalStatus::ok);
    hal::GripperReading r;
    ASSERT_EQ(gripper->read(r), HalStatus::ok);
    tick(clock, config.reset_hold_s);
    ASSERT_EQ(gripper->read(r), HalStatus::ok);  // writes rACT = 1
    emulator.advance(0.5);
    tick(clock, 0.05);  // past any min_poll_period_s a test sets
    ASSERT_EQ(gripper->read(r), HalStatus::ok);
    ASSERT_TRUE(gripper->activated());
  }

  hal::GripperReading read_ok() {
    hal::GripperReading r;
    EXPECT_EQ(gripper->read(r), HalStatus::ok);
    return r;
  }

  hal::ManualClock clock;
  ModbusEmulator emulator{emulator_config()};
  RobotiqGripperConfig config;
  std::unique_ptr<RobotiqGripper> gripper;
};

TEST_F(RobotiqGripperTest, ActivationSequence) {
  make();
  ASSERT_EQ(gripper->configure(), HalStatus::ok);
  ASSERT_EQ(gripper->start(), HalStatus::ok);
  // start(): status read (FC04), then the reset write {0, 0, 0}.
  EXPECT_EQ(emulator.counters().command_writes, 1u);
  EXPECT_EQ(emulator.holding_register(r2f::kCommandRegister), 0x0000);
  EXPECT_FALSE(gripper->using_holding_registers());
  EXPECT_EQ(gripper->move_to(0.02, 0.1, 50), HalStatus::wrong_state);  // not activated yet
  EXPECT_EQ(gripper->counters().rejected_writes, 1u);

  hal::GripperReading r = read_ok();
  EXPECT_EQ(r.header.status_bits & hal::kGripperActivated, 0u);
  EXPECT_EQ(r.header.sequence, 1u);
  tick(clock, 0.1);
  r = read_ok();
  EXPECT_EQ(emulator.counters().command_writes, 1u);  // still holding the reset
  tick(clock, 0.1);
  r = read_ok();  // reset_hold_s passed: rACT = 1 goes out
  EXPECT_EQ(emulator.counters().command_writes, 2u);
  EXPECT_EQ(emulator.holding_register(r2f::kCommandRegister), 0x0100);
  EXPECT_EQ(emulator.gripper().status.gsta, r2f::kStaActivating);
  r = read_ok();
  EXPECT_EQ(r.header.status_bits & hal::kGripperActivated, 0u);
  EXPECT_FALSE(gripper->activated());
  emulator.advance(0.5);
  r = read_ok();
  EXPECT_NE(r.header.status_bits & hal::kGripperActivated, 0u);
  EXPECT_TRUE(gripper->activated());
  EXPECT_NEAR(r.width_m, 0.085, 1e-12);
  EXPECT_EQ(gripper->driver_counters().activations, 1u);
  EXPECT_EQ(gripper->driver_counters().activation_retries, 0u);
  EXPECT_EQ(gripper->counters().samples, 5u);
  EXPECT_EQ(gripper->counters().faults(), 0u);
}

TEST_F(RobotiqGripperTest, ActivationTimesOutAndStartsOver) {
  config.activation_timeout_s = 1.0;
  make();
  ASSERT_EQ(gripper->configure(), HalStatus::ok);
  ASSERT_EQ(gripper->start(), HalStatus::ok);
  tick(clock, 0.2);
  (void)read_ok();   // rACT = 1
  tick(clock, 1.0);  // the emulator never advances: activation never completes
  (void)read_ok();
  EXPECT_EQ(gripper->driver_counters().activation_retries, 1u);
  EXPECT_EQ(gripper->driver_counters().activations, 2u);
  EXPECT_EQ(emulator.holding_register(r2f::kCommandRegister), 0x0000);  // reset again
}

TEST_F(RobotiqGripperTest, ActivationPolicies) {
  activate();
  const std::uint64_t writes = emulator.counters().command_writes;
  ASSERT_EQ(gripper->stop(), HalStatus::ok);
  ASSERT_EQ(gripper->cleanup(), HalStatus::ok);
  // if_needed: the gripper is activated already; nothing is written.
  make();
  ASSERT_EQ(gripper->configure(), HalStatus::ok);
  ASSERT_EQ(gripper->start(), HalStatus::ok);
  EXPECT_TRUE(gripper->activated());
  EXPECT_EQ(emulator.counters().command_writes, writes);
  EXPECT_EQ(gripper->driver_counters().activations, 0u);
  ASSERT_EQ(gripper->stop(), HalStatus::ok);
  ASSERT_EQ(gripper->cleanup(), HalStatus::ok);
  // always: the reset goes out even so.
  config.activation = ActivationPolicy::always;
  make();
  ASSERT_EQ(gripper->configure(), HalStatus::ok);
  ASSERT_EQ(gripper->start(), HalStatus::ok);
  EXPECT_EQ(emulator.counters().command_writes, writes + 1);
  EXPECT_EQ(emulator.gripper().status.gsta, r2f::kStaReset);
  EXPECT_EQ(gripper->reactivate(), HalStatus::ok);
  EXPECT_EQ(gripper->driver_counters().activations, 2u);
}

TEST_F(RobotiqGripperTest, MoveReachesTheTarget) {
  activate();
  const std::uint64_t writes = emulator.counters().command_writes;
  ASSERT_EQ(gripper->move_to(0.04, 0.15, 62.15), HalStatus::ok);
  // Last command had rGTO clear: one write {0x0900, rPR, rSP << 8 | rFR}.
  EXPECT_EQ(emulator.counters().command_writes, writes + 1);
  EXPECT_EQ(emulator.holding_register(r2f::kCommandRegister), 0x0900);
  EXPECT_EQ(emulator.holding_register(r2f::kCommandRegister + 1), 135);     // 0.04 m on a 2F-85
  EXPECT_EQ(emulator.holding_register(r2f::kCommandRegister + 2), 0xff32);  // speed 255, force 50
  hal::GripperReading r = read_ok();
  EXPECT_NE(r.header.status_bits & hal::kGripperMoving, 0u);
  EXPECT_NEAR(r.target_width_m, 0.04, kByteWidthM);
  emulator.advance(0.1);
  r = read_ok();
  EXPECT_NEAR(r.width_m, 0.085 - 0.015, kByteWidthM);
  emulator.advance(1.0);
  r = read_ok();
  EXPECT_EQ(r.header.status_bits, hal::kGripperActivated | hal::kGripperAtTarget);
  EXPECT_NEAR(r.width_m, 0.04, kByteWidthM);
  EXPECT_NEAR(r.width_m, emulator.gripper().width_m, kByteWidthM);
  EXPECT_TRUE(std::isnan(r.force_n));
  // The next move re-arms rGTO first: two writes, and the gripper moves again.
  ASSERT_EQ(gripper->move_to(0.06, 0.15, 100), HalStatus::ok);
  EXPECT_EQ(emulator.counters().command_writes, writes + 3);
  emulator.advance(1.0);
  r = read_ok();
  EXPECT_NEAR(r.width_m, 0.06, kByteWidthM);
  EXPECT_NE(r.header.status_bits & hal::kGripperAtTarget, 0u);
}

TEST_F(RobotiqGripperTest, OpenAndFreeze) {
  activate();
  ASSERT_EQ(gripper->move_to(0.0, 0.15, 50), HalStatus::ok);
  emulator.advance(0.2);  // 30 mm closed
  ASSERT_EQ(gripper->freeze(), HalStatus::ok);
  EXPECT_EQ(emulator.holding_register(r2f::kCommandRegister), 0x0100);  // rGTO cleared
  emulator.advance(1.0);
  hal::GripperReading r = read_ok();
  EXPECT_NEAR(r.width_m, 0.055, kByteWidthM);
  EXPECT_EQ(r.header.status_bits & (hal::kGripperMoving | hal::kGripperAtTarget), 0u);
  ASSERT_EQ(gripper->open(0.1), HalStatus::ok);
  EXPECT_EQ(emulator.holding_register(r2f::kCommandRegister + 1), 0);  // open_byte
  EXPECT_EQ(emulator.holding_register(r2f::kCommandRegister + 2) & 0xff, r2f::force_to_byte(100, config.scaling));
  emulator.advance(1.0);
  r = read_ok();
  EXPECT_NEAR(r.width_m, 0.085, 1e-12);
}

TEST_F(RobotiqGripperTest, RigidObjectIsDetected) {
  emulator.set_object(0.05, std::numeric_limits<double>::infinity());
  activate();
  ASSERT_EQ(gripper->move_to(0.0, 0.05, 60), HalStatus::ok);
  emulator.advance(5.0);
  const hal::GripperReading r = read_ok();
  EXPECT_EQ(r.header.status_bits, hal::kGripperActivated | hal::kGripperObjectDetected);
  EXPECT_NEAR(r.width_m, 0.05, kByteWidthM);
  EXPECT_NEAR(r.target_width_m, 0.0, 1e-12);
  EXPECT_GT(r.current_a, 0.0);  // the model draws current while squeezing
  EXPECT_NEAR(r.current_a, 0.01 * emulator.gripper().status.current, 1e-12);
}

TEST_F(RobotiqGripperTest, SoftObjectIsSqueezedToTheForceLimit) {
  emulator.set_object(0.05, 2000.0);  // 2 N/mm
  activate();
  ASSERT_EQ(gripper->move_to(0.0, 0.05, 60), HalStatus::ok);
  emulator.advance(5.0);
  const hal::GripperReading r = read_ok();
  EXPECT_NE(r.header.status_bits & hal::kGripperObjectDetected, 0u);
  const double force_limit = r2f::byte_to_force(r2f::force_to_byte(60, config.scaling), config.scaling);
  EXPECT_NEAR(emulator.gripper().grip_force_n, force_limit, 1e-9);
  EXPECT_NEAR(r.width_m, 0.05 - force_limit / 2000.0, kByteWidthM);
}

TEST_F(RobotiqGripperTest, FaultCodeIsDecodedIntoStatusBits) {
  activate();
  emulator.set_gripper_fault(0x0e);
  hal::GripperReading r = read_ok();
  EXPECT_EQ(hal::gripper_fault_code(r.header.status_bits), hal::kGripperFaultOverCurrent);
  EXPECT_EQ(gripper->counters().fault_samples, 1u);
  EXPECT_EQ(gripper->last_status().gflt, 0x0e);
  // Writes still go out: the gripper decides (and the emulator's fingers stay frozen).
  EXPECT_EQ(gripper->move_to(0.0, 0.1, 50), HalStatus::ok);
  emulator.advance(1.0);
  r = read_ok();
  EXPECT_NEAR(r.width_m, 0.085, 1e-12);
  emulator.set_gripper_fault(0x00);
  r = read_ok();
  EXPECT_EQ(r.header.status_bits & hal::kGripperFaultMask, 0u);
  EXPECT_EQ(gripper->counters().fault_samples, 2u);
}

// The guard's default gripper mask on a real Robotiq status word, read over Modbus TCP: every
// state the 2F-85 passes through on the way to squeezing an object (reset, activating,
// activated, moving, object detected, at target) is clear of it; every non-zero gFLT and kFLT
// value is caught.
TEST_F(RobotiqGripperTest, TheGuardsDefaultMaskTellsStatesFromFaults) {
  const std::uint32_t mask = GraspGuardConfig{}.gripper_fault_mask;
  const auto sample_bits = [this] {
    hal::GripperReading r;
    EXPECT_EQ(gripper->read(r), HalStatus::ok);
    GripperSample sample;
    hal::update_gripper_sample(HalStatus::ok, r, 0, sample);
    return sample.status_bits;
  };
  emulator.set_object(0.05, 2000.0);
  make();
  ASSERT_EQ(gripper->configure(), HalStatus::ok);
  ASSERT_EQ(gripper->start(), HalStatus::ok);
  std::uint32_t seen = 0;
  const auto expect_no_fault = [&](const char* state) {
    const std::uint32_t bits = sample_bits();
    seen |= bits;
    EXPECT_EQ(bits & mask, 0u) << state << ": status " << bits;
  };
  expect_no_fault("reset");
  tick(clock, config.reset_hold_s);
  expect_no_fault("activating");
  emulator.advance(0.5);
  tick(clock, 0.05);
  expect_no_fault("activated");
  ASSERT_TRUE(gripper->activated());
  ASSERT_EQ(gripper->move_to(0.0, 0.02, 60), HalStatus::ok);
  emulator.advance(0.1);
  expect_no_fault("moving");
  emulator.advance(5.0);
  expect_no_fault("object detected");
  ASSERT_EQ(gripper->move_to(0.08, 0.1, 60), HalStatus::ok);
  emulator.advance(5.0);
  expect_no_fault("at target");
  EXPECT_EQ(seen & 0x0fu,
            hal::kGripperActivated | hal::kGripperMoving | hal::kGripperObjectDetected | hal::kGripperAtTarget);
  for (int gflt = 0; gflt <= 0x0f; ++gflt) {
    for (int kflt = 0; kflt <= 0x0f; kflt += 0x05) {
      if (gflt == 0 && kflt == 0) continue;
      emulator.set_gripper_fault(static_cast<std::uint8_t>(gflt | kflt << 4));
      EXPECT_NE(sample_bits() & mask, 0u) << "gFLT " << gflt << " kFLT " << kflt;
    }
  }
  emulator.set_gripper_fault(0x00);
  EXPECT_EQ(sample_bits() & mask, 0u);
}

TEST_F(RobotiqGripperTest, FallsBackToFc03WhenFc04IsRefused) {
  emulator.set_fc04_supported(false);
  activate();
  EXPECT_TRUE(gripper->using_holding_registers());
  EXPECT_EQ(gripper->driver_counters().fc03_fallbacks, 1u);
  EXPECT_EQ(gripper->link_counters().exceptions, 1u);
  EXPECT_EQ(emulator.counters().exceptions, 1u);
  const hal::GripperReading r = read_ok();
  EXPECT_NE(r.header.status_bits & hal::kGripperActivated, 0u);
  EXPECT_EQ(gripper->link_counters().exceptions, 1u);  // no FC04 after the switch
  EXPECT_EQ(gripper->counters().faults(), 0u);
}

TEST_F(RobotiqGripperTest, ForcedFc04FailsWhenRefused) {
  emulator.set_fc04_supported(false);
  config.status_read = StatusRead::input_registers;
  make();
  ASSERT_EQ(gripper->configure(), HalStatus::ok);
  EXPECT_EQ(gripper->start(), HalStatus::io_error);
  EXPECT_EQ(gripper->state(), hal::LifecycleState::inactive);
  EXPECT_EQ(gripper->driver_counters().fc03_fallbacks, 0u);
  // FC03 forced works with it.
  ASSERT_EQ(gripper->cleanup(), HalStatus::ok);
  config.status_read = StatusRead::holding_registers;
  make();
  ASSERT_EQ(gripper->configure(), HalStatus::ok);
  EXPECT_EQ(gripper->start(), HalStatus::ok);
  EXPECT_TRUE(gripper->using_holding_registers());
}

TEST_F(RobotiqGripperTest, UnansweredPollIsATimeout) {
  activate();
  emulator.drop_replies(1);
  hal::GripperReading r;
  r.width_m = -1.0;
  EXPECT_EQ(gripper->read(r), HalStatus::timeout);  // waits the 2 s budget once
  EXPECT_EQ(r.width_m, -1.0);                       // not written on failure
  EXPECT_EQ(gripper->counters().timeouts, 1u);
  EXPECT_EQ(gripper->link_counters().timeouts, 1u);
  EXPECT_EQ(emulator.counters().dropped, 1u);
  r = read_ok();
  EXPECT_EQ(gripper->link_counters().flushes, 1u);
  EXPECT_NE(r.header.status_bits & hal::kGripperActivated, 0u);
  // Sequence numbers count answered polls only: no gap, nothing counted as dropped.
  EXPECT_EQ(gripper->counters().dropped, 0u);
}

TEST_F(RobotiqGripperTest, DamagedAnswerIsAnIoError) {
  activate();
  emulator.corrupt_replies(1);
  hal::GripperReading r;
  EXPECT_EQ(gripper->read(r), HalStatus::io_error);
  EXPECT_EQ(gripper->counters().io_errors, 1u);
  EXPECT_EQ(gripper->link_counters().bad_responses, 1u);
  EXPECT_EQ(gripper->link_counters().last_errno, EMBBADDATA);  // wrong transaction ID
  r = read_ok();
  // A damaged answer to a write: the write is reported failed, though the gripper acted on it.
  emulator.corrupt_replies(1);
  EXPECT_EQ(gripper->move_to(0.03, 0.15, 50), HalStatus::io_error);
  EXPECT_EQ(gripper->counters().rejected_writes, 1u);
  EXPECT_EQ(emulator.gripper().command.action, r2f::kActionActivate | r2f::kActionGoTo);
  EXPECT_EQ(emulator.counters().corrupted, 2u);
}

TEST_F(RobotiqGripperTest, DisconnectThenReconnect) {
  activate();
  const std::uint64_t connections = emulator.counters().connections;
  ASSERT_TRUE(emulator.disconnect_clients());
  hal::GripperReading r;
  EXPECT_EQ(gripper->read(r), HalStatus::disconnected);
  EXPECT_EQ(gripper->counters().disconnected, 1u);
  EXPECT_EQ(gripper->counters().disconnects, 1u);
  EXPECT_EQ(gripper->link_counters().disconnects, 1u);
  // Within reconnect_interval_s: no attempt, no I/O.
  EXPECT_EQ(gripper->read(r), HalStatus::disconnected);
  EXPECT_EQ(gripper->move_to(0.02, 0.1, 50), HalStatus::disconnected);
  EXPECT_EQ(gripper->link_counters().reconnect_attempts, 0u);
  EXPECT_EQ(gripper->counters().disconnects, 1u);  // still the same outage
  tick(clock, kPastReconnectS);
  r = read_ok();
  EXPECT_NE(r.header.status_bits & hal::kGripperActivated, 0u);
  EXPECT_EQ(gripper->link_counters().reconnect_attempts, 1u);
  EXPECT_EQ(gripper->link_counters().reconnects, 1u);
  EXPECT_EQ(gripper->counters().reconnects, 1u);
  EXPECT_EQ(gripper->counters().disconnected, 3u);  // two reads and one write
  EXPECT_EQ(emulator.counters().connections, connections + 1);
  EXPECT_EQ(gripper->move_to(0.02, 0.1, 50), HalStatus::ok);
}

TEST_F(RobotiqGripperTest, RefusedReconnectionsAreCounted) {
  activate();
  emulator.set_refuse_connections(true);
  ASSERT_TRUE(emulator.disconnect_clients());
  hal::GripperReading r;
  EXPECT_EQ(gripper->read(r), HalStatus::disconnected);
  tick(clock, kPastReconnectS);
  // The TCP connect succeeds (the kernel accepts), then the server drops the connection.
  EXPECT_EQ(gripper->read(r), HalStatus::disconnected);
  EXPECT_EQ(gripper->link_counters().reconnect_attempts, 1u);
  EXPECT_EQ(gripper->link_counters().disconnects, 2u);
  EXPECT_EQ(gripper->counters().disconnects, 1u);  // one outage as the hal sees it
  EXPECT_EQ(gripper->counters().reconnects, 0u);
  EXPECT_EQ(emulator.counters().refused, 1u);
  emulator.set_refuse_connections(false);
  tick(clock, kPastReconnectS);
  r = read_ok();
  EXPECT_EQ(gripper->link_counters().reconnect_attempts, 2u);
  EXPECT_EQ(gripper->counters().reconnects, 1u);
}

TEST_F(RobotiqGripperTest, ServerGoneMeansDisconnectedUntilItIsBack) {
  activate();
  emulator.stop();
  hal::GripperReading r;
  EXPECT_EQ(gripper->read(r), HalStatus::disconnected);
  for (int i = 0; i < 3; ++i) {
    tick(clock, kPastReconnectS);
    EXPECT_EQ(gripper->read(r), HalStatus::disconnected);  // connection refused
  }
  EXPECT_EQ(gripper->link_counters().reconnect_attempts, 3u);
  EXPECT_EQ(gripper->link_counters().reconnects, 0u);
  EXPECT_EQ(gripper->link_counters().last_errno, ECONNREFUSED);
}

TEST_F(RobotiqGripperTest, MinPollPeriodRateLimitsWithoutIo) {
  config.min_poll_period_s = 0.01;
  activate();
  const std::uint64_t requests = emulator.counters().requests;
  hal::GripperReading r;
  EXPECT_EQ(gripper->read(r), HalStatus::no_data);
  EXPECT_EQ(emulator.counters().requests, requests);
  EXPECT_EQ(gripper->driver_counters().polls_skipped, 1u);
  tick(clock, 0.01);
  EXPECT_EQ(gripper->read(r), HalStatus::ok);
  EXPECT_EQ(emulator.counters().requests, requests + 1);
}

TEST_F(RobotiqGripperTest, ConfigurationErrors) {
  config.scaling.stroke_m = -1;
  make();
  EXPECT_EQ(gripper->configure(), HalStatus::invalid_argument);
  config = tcp_config(emulator.port());
  config.open_force_n = 0;
  make();
  EXPECT_EQ(gripper->configure(), HalStatus::invalid_argument);
  config = tcp_config(emulator.port());
  config.link.host = "not an address";
  make();
  EXPECT_EQ(gripper->configure(), HalStatus::invalid_argument);
  // Nobody listening: refused at configure.
  const std::uint16_t port = emulator.port();
  emulator.stop();
  config = tcp_config(port);
  make();
  EXPECT_EQ(gripper->configure(), HalStatus::disconnected);
  EXPECT_EQ(gripper->state(), hal::LifecycleState::unconfigured);
  // A serial device that does not exist.
  config = RobotiqGripperConfig{};
  config.link.device = "/nonexistent/ttyUSB9";
  make();
  EXPECT_EQ(gripper->configure(), HalStatus::disconnected);
}

TEST(RobotiqGripperRtuTest, ActivationMoveAndDamagedCrcOverAPseudoTerminal) {
  ModbusEmulator emulator(emulator_config(EmulatorTransport::rtu_pty));
  std::string error;
  ASSERT_TRUE(emulator.start(&error)) << error;
  hal::ManualClock clock;
  RobotiqGripperConfig config;
  config.link.device = emulator.device_path();
  config.link.response_timeout_s = kAnswerBudgetS;
  config.reset_hold_s = 0.2;
  RobotiqGripper gripper(clock, config);
  ASSERT_EQ(gripper.configure(), HalStatus::ok);
  ASSERT_EQ(gripper.start(), HalStatus::ok);
  hal::GripperReading r;
  tick(clock, 0.2);
  ASSERT_EQ(gripper.read(r), HalStatus::ok);
  emulator.advance(0.5);
  ASSERT_EQ(gripper.read(r), HalStatus::ok);
  ASSERT_TRUE(gripper.activated());
  ASSERT_EQ(gripper.move_to(0.03, 0.15, 40), HalStatus::ok);
  emulator.advance(1.0);
  ASSERT_EQ(gripper.read(r), HalStatus::ok);
  EXPECT_NEAR(r.width_m, 0.03, kByteWidthM);
  EXPECT_NE(r.header.status_bits & hal::kGripperAtTarget, 0u);
  emulator.corrupt_replies(1);
  EXPECT_EQ(gripper.read(r), HalStatus::io_error);
  EXPECT_EQ(gripper.link_counters().last_errno, EMBBADCRC);
  EXPECT_EQ(gripper.link_counters().bad_responses, 1u);
  EXPECT_EQ(gripper.read(r), HalStatus::ok);
  EXPECT_EQ(gripper.counters().io_errors, 1u);
}

TEST(RobotiqGripperRtuTest, WrongSlaveIdTimesOut) {
  ModbusEmulator emulator(emulator_config(EmulatorTransport::rtu_pty));
  std::string error;
  ASSERT_TRUE(emulator.start(&error)) << error;
  hal::ManualClock clock;
  RobotiqGripperConfig config;
  config.link.device = emulator.device_path();
  config.link.response_timeout_s = 0.5;  // the answer never comes: the budget is spent once
  config.link.slave_id = 10;
  RobotiqGripper gripper(clock, config);
  ASSERT_EQ(gripper.configure(), HalStatus::ok);
  EXPECT_EQ(gripper.start(), HalStatus::timeout);
  EXPECT_EQ(gripper.link_counters().timeouts, 1u);
  EXPECT_EQ(emulator.counters().requests, 0u);
}

}  // namespace
}  // namespace pliant::drivers::modbus
