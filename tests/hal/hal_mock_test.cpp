// The mock devices: stamps and sequence numbers, commands, sensor frames, and every fault kind
// injected exactly as scheduled and counted, with recovery afterwards.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "hal_fixture.hpp"
#include "pliant/hal/mock/mock_cameras.hpp"

namespace pliant::hal {
namespace {

using test::event;
using test::SteppedClock;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

struct GripperRig {
  SteppedClock t;
  SimulatedGrasp plant{t.clock};
  MockGripper gripper{plant, t.clock, config()};
  static MockGripperConfig config() {
    MockGripperConfig c;
    c.seed = 7;
    return c;
  }
  GripperRig() {
    EXPECT_EQ(plant.configure(test::small_grasp()), HalStatus::ok);
    EXPECT_EQ(gripper.configure(), HalStatus::ok);
    EXPECT_EQ(gripper.start(), HalStatus::ok);
  }
};

TEST(HalMockGripper, OneSamplePerPeriodWithMonotonicStampsAndSequence) {
  GripperRig rig;
  GripperReading r;
  // Sample 0 is captured at start.
  ASSERT_EQ(rig.gripper.read(r), HalStatus::ok);
  EXPECT_EQ(r.header.sequence, 1u);
  EXPECT_EQ(r.header.stamp_s, 1.0);
  EXPECT_EQ(rig.gripper.read(r), HalStatus::no_data);  // nothing new within the period
  double previous = r.header.stamp_s;
  for (int k = 1; k <= 50; ++k) {
    rig.t.step();
    ASSERT_EQ(rig.gripper.read(r), HalStatus::ok) << k;
    EXPECT_EQ(r.header.sequence, static_cast<std::uint64_t>(k + 1));
    EXPECT_GT(r.header.stamp_s, previous);
    EXPECT_NEAR(r.header.stamp_s, rig.t.now(), 1e-12);
    previous = r.header.stamp_s;
    EXPECT_NEAR(r.width_m, 0.034, 30e-6);  // 5 um noise
    EXPECT_NE(r.header.status_bits & kGripperActivated, 0u);
  }
  // Reading every other period: the skipped samples are gaps, counted as dropped.
  rig.t.step(2);
  ASSERT_EQ(rig.gripper.read(r), HalStatus::ok);
  EXPECT_EQ(r.header.sequence, 53u);
  EXPECT_EQ(rig.gripper.counters().dropped, 1u);
  EXPECT_EQ(rig.gripper.counters().samples, 52u);
  EXPECT_EQ(rig.gripper.counters().no_data, 1u);
}

TEST(HalMockGripper, MovesRateLimitedAndStopsAtTheForceLimit) {
  GripperRig rig;
  const double extent = rig.plant.extent_m();  // 32 mm
  EXPECT_NEAR(extent, 0.032, 1e-12);
  ASSERT_EQ(rig.gripper.move_to(0.030, 0.01, 3.0), HalStatus::ok);  // 10 mm/s, stop at 3 N
  GripperReading r;
  rig.t.step(100);  // 100 ms: 1 mm at most
  ASSERT_EQ(rig.gripper.read(r), HalStatus::ok);
  EXPECT_NEAR(rig.plant.width_m(), 0.033, 1e-9);
  EXPECT_NE(r.header.status_bits & kGripperMoving, 0u);
  EXPECT_EQ(rig.plant.grip_force_n(), 0.0);
  rig.t.step(400);
  ASSERT_EQ(rig.gripper.read(r), HalStatus::ok);
  // 2000 N/m x closure reaches 3 N at 1.5 mm of closure, before the 2 mm target.
  EXPECT_TRUE(rig.plant.object_detected());
  EXPECT_NE(r.header.status_bits & kGripperObjectDetected, 0u);
  EXPECT_EQ(r.header.status_bits & kGripperMoving, 0u);
  EXPECT_NEAR(rig.plant.closure_m(), 0.0015, 2e-5);
  EXPECT_NEAR(r.force_n, 2000 * rig.plant.closure_m(), 0.03);
  EXPECT_NEAR(r.current_a, 0.05 + r.force_n / 100, 0.002);
  // Freeze, then open at the speed limit (the configured 0.15 m/s caps a faster request).
  ASSERT_EQ(rig.gripper.freeze(), HalStatus::ok);
  const double held = rig.plant.width_m();
  rig.t.step(10);
  ASSERT_EQ(rig.gripper.read(r), HalStatus::ok);
  EXPECT_EQ(rig.plant.width_m(), held);
  ASSERT_EQ(rig.gripper.open(1.0), HalStatus::ok);
  rig.t.step(10);
  ASSERT_EQ(rig.gripper.read(r), HalStatus::ok);
  EXPECT_NEAR(rig.plant.width_m(), held + 0.0015, 1e-9);
  rig.t.step(1000);
  ASSERT_EQ(rig.gripper.read(r), HalStatus::ok);
  EXPECT_EQ(rig.plant.width_m(), rig.plant.max_width_m());
  EXPECT_NE(r.header.status_bits & kGripperAtTarget, 0u);
  EXPECT_EQ(rig.plant.grip_force_n(), 0.0);
}

TEST(HalMockGripper, RefusesBadCommands) {
  GripperRig rig;
  EXPECT_EQ(rig.gripper.move_to(kNaN, 0.01, 1), HalStatus::invalid_argument);
  EXPECT_EQ(rig.gripper.move_to(0.02, 0, 1), HalStatus::invalid_argument);
  EXPECT_EQ(rig.gripper.move_to(0.02, 0.01, -1), HalStatus::invalid_argument);
  EXPECT_EQ(rig.gripper.open(std::numeric_limits<double>::infinity()), HalStatus::invalid_argument);
  GripperCommand bad;
  bad.kind = static_cast<GripperCommandKind>(9);
  EXPECT_EQ(rig.gripper.write(bad), HalStatus::invalid_argument);
  EXPECT_EQ(rig.gripper.counters().rejected_writes, 5u);
  // Out-of-range widths are clamped, not refused: the jaws never pass the hard stop.
  EXPECT_EQ(rig.gripper.move_to(-1.0, 0.15, 1000), HalStatus::ok);
  rig.t.step(1000);
  GripperReading r;
  ASSERT_EQ(rig.gripper.read(r), HalStatus::ok);
  EXPECT_NEAR(rig.plant.width_m(), rig.plant.min_width_m(), 1e-12);
  MockGripperConfig broken;
  broken.current_gain_n_per_a = 0;
  MockGripper g(rig.plant, rig.t.clock, broken);
  EXPECT_EQ(g.configure(), HalStatus::invalid_argument);
  EXPECT_EQ(g.state(), LifecycleState::unconfigured);
  SimulatedGrasp unconfigured(rig.t.clock);
  MockGripper orphan(unconfigured, rig.t.clock);
  EXPECT_EQ(orphan.configure(), HalStatus::invalid_argument);
}

// Every sample fault, on a window covering exactly the samples at 1.011 .. 1.015 s.
TEST(HalMockGripper, SampleFaultsHitExactlyTheScheduledSamples) {
  const FaultKind kinds[] = {FaultKind::drop, FaultKind::freeze_data, FaultKind::freeze_stamp,
                             FaultKind::nan,  FaultKind::stamp_jump,  FaultKind::fault_bits};
  for (FaultKind kind : kinds) {
    SCOPED_TRACE(fault_kind_name(kind));
    GripperRig rig;
    ASSERT_EQ(rig.gripper.move_to(0.02, 0.01, 100), HalStatus::ok);
    ASSERT_EQ(rig.gripper.add_fault(event(kind, 1.0105, 0.005)), HalStatus::ok);
    GripperReading r, before;
    int affected = 0;
    for (int k = 1; k <= 30; ++k) {
      rig.t.step();
      const HalStatus s = rig.gripper.read(r);
      const bool inside = k >= 11 && k <= 15;
      if (k == 10) before = r;
      if (kind == FaultKind::drop) {
        EXPECT_EQ(s, inside ? HalStatus::no_data : HalStatus::ok) << k;
        affected += inside ? 1 : 0;
        continue;
      }
      ASSERT_EQ(s, HalStatus::ok) << k;
      EXPECT_EQ(r.header.sequence, static_cast<std::uint64_t>(k + 1));
      if (!inside) {
        EXPECT_TRUE(std::isfinite(r.width_m));
        EXPECT_NEAR(r.header.stamp_s, rig.t.now(), 1e-12);
        EXPECT_EQ(gripper_fault_code(r.header.status_bits), 0) << k;
        continue;
      }
      ++affected;
      switch (kind) {
        case FaultKind::freeze_data:
          EXPECT_EQ(std::memcmp(&r.width_m, &before.width_m, sizeof(double)), 0);
          EXPECT_EQ(std::memcmp(&r.force_n, &before.force_n, sizeof(double)), 0);
          EXPECT_NEAR(r.header.stamp_s, rig.t.now(), 1e-12);
          break;
        case FaultKind::freeze_stamp:
          EXPECT_EQ(r.header.stamp_s, before.header.stamp_s);
          EXPECT_EQ(r.width_m, before.width_m);
          break;
        case FaultKind::nan:
          EXPECT_TRUE(std::isnan(r.width_m) && std::isnan(r.force_n) && std::isnan(r.current_a));
          break;
        case FaultKind::stamp_jump: EXPECT_NEAR(r.header.stamp_s, rig.t.now() + 0.5, 1e-12); break;
        case FaultKind::fault_bits:
          EXPECT_EQ(gripper_fault_code(r.header.status_bits), kGripperFaultOverCurrent);
          EXPECT_NE(r.header.status_bits & kGripperFaultMask, 0u);
          break;
        default: break;
      }
    }
    EXPECT_EQ(affected, 5);
    EXPECT_EQ(rig.gripper.fault_counters().of(kind), 5u);
    EXPECT_EQ(rig.gripper.fault_counters().total(), 5u);
    // Sample 0 (captured at start) was never read: one drop besides the injected ones.
    EXPECT_EQ(rig.gripper.counters().dropped, kind == FaultKind::drop ? 6u : 1u);
    EXPECT_EQ(rig.gripper.counters().fault_samples, kind == FaultKind::fault_bits ? 5u : 0u);
  }
}

TEST(HalMockGripper, FaultBitsStopTheActuatorAndRefuseCommands) {
  GripperRig rig;
  ASSERT_EQ(rig.gripper.move_to(0.02, 0.01, 100), HalStatus::ok);
  ASSERT_EQ(rig.gripper.add_fault(event(FaultKind::fault_bits, 1.0205, 0.05, 0x0a00)), HalStatus::ok);
  GripperReading r;
  rig.t.step(21);
  ASSERT_EQ(rig.gripper.read(r), HalStatus::ok);
  EXPECT_EQ(gripper_fault_code(r.header.status_bits), kGripperFaultUnderVoltage);
  const double held = rig.plant.width_m();
  EXPECT_EQ(rig.gripper.move_to(0.01, 0.01, 100), HalStatus::device_fault);
  EXPECT_EQ(rig.gripper.counters().device_faults, 1u);
  rig.t.step(20);
  ASSERT_EQ(rig.gripper.read(r), HalStatus::ok);
  EXPECT_EQ(rig.plant.width_m(), held);
  rig.t.step(40);  // fault over: the jaws hold until a new command
  ASSERT_EQ(rig.gripper.read(r), HalStatus::ok);
  EXPECT_EQ(gripper_fault_code(r.header.status_bits), 0);
  EXPECT_EQ(rig.plant.width_m(), held);
  ASSERT_EQ(rig.gripper.move_to(0.02, 0.01, 100), HalStatus::ok);
  rig.t.step(10);
  ASSERT_EQ(rig.gripper.read(r), HalStatus::ok);
  EXPECT_LT(rig.plant.width_m(), held);
}

TEST(HalMockGripper, ModbusTimeoutFailsReadsAndWritesAndTheLastCommandRuns) {
  GripperRig rig;
  ASSERT_EQ(rig.gripper.move_to(0.031, 0.01, 100), HalStatus::ok);
  ASSERT_EQ(rig.gripper.add_fault(event(FaultKind::timeout, 1.0095, 0.010)), HalStatus::ok);
  GripperReading r;
  int timeouts = 0;
  for (int k = 1; k <= 30; ++k) {
    rig.t.step();
    const HalStatus s = rig.gripper.read(r);
    timeouts += s == HalStatus::timeout ? 1 : 0;
    if (k == 12) {
      EXPECT_EQ(rig.gripper.freeze(), HalStatus::timeout);  // lost
    }
  }
  EXPECT_EQ(timeouts, 10);
  EXPECT_EQ(rig.gripper.counters().timeouts, 11u);
  EXPECT_EQ(rig.gripper.fault_counters().of(FaultKind::timeout), 11u);
  EXPECT_EQ(rig.gripper.counters().dropped, 1u + 10u);  // sample 0, never read, and those due during the outage
  EXPECT_LT(rig.plant.width_m(), 0.034 - 0.0002);       // the freeze never arrived
  EXPECT_EQ(rig.gripper.add_fault(event(FaultKind::bus_off, 2, 1)), HalStatus::unsupported);
  EXPECT_EQ(rig.gripper.add_fault(event(FaultKind::drop, 2, 0)), HalStatus::invalid_argument);
}

TEST(HalMockGripper, RecoversAfterADisconnect) {
  GripperRig rig;
  ASSERT_EQ(rig.gripper.add_fault(event(FaultKind::disconnect, 1.0045, 0.020)), HalStatus::ok);
  GripperReading r;
  std::vector<HalStatus> statuses;
  for (int k = 1; k <= 40; ++k) {
    rig.t.step();
    statuses.push_back(rig.gripper.read(r));
  }
  for (int k = 1; k <= 40; ++k) {
    const bool down = k >= 5 && k <= 24;
    EXPECT_EQ(statuses[static_cast<std::size_t>(k - 1)], down ? HalStatus::disconnected : HalStatus::ok) << k;
  }
  EXPECT_EQ(r.header.sequence, 41u);
  const DeviceCounters& c = rig.gripper.counters();
  EXPECT_EQ(c.disconnected, 20u);
  EXPECT_EQ(c.disconnects, 1u);
  EXPECT_EQ(c.reconnects, 1u);
  EXPECT_EQ(c.dropped, 1u + 20u);  // sample 0, never read, and the outage's
  EXPECT_EQ(rig.gripper.fault_counters().of(FaultKind::disconnect), 20u);
  // Commands work again.
  EXPECT_EQ(rig.gripper.move_to(0.03, 0.01, 10), HalStatus::ok);
}

TEST(HalMockGripper, SequenceContinuesAcrossStopAndStart) {
  GripperRig rig;
  GripperReading r;
  rig.t.step(3);
  ASSERT_EQ(rig.gripper.read(r), HalStatus::ok);
  EXPECT_EQ(r.header.sequence, 4u);
  ASSERT_EQ(rig.gripper.stop(), HalStatus::ok);
  EXPECT_EQ(rig.gripper.read(r), HalStatus::wrong_state);
  rig.t.step(100);
  ASSERT_EQ(rig.gripper.start(), HalStatus::ok);
  ASSERT_EQ(rig.gripper.read(r), HalStatus::ok);
  EXPECT_EQ(r.header.sequence, 5u);
  EXPECT_NEAR(r.header.stamp_s, rig.t.now(), 1e-12);
  EXPECT_EQ(rig.gripper.counters().dropped, 3u);  // samples 1..3 were never read
}

// --- force/torque ---------------------------------------------------------------------------------

TEST(HalMockForceTorque, ReportsTheGripForceInTheSensorFrame) {
  SteppedClock t;
  SimulatedGrasp plant(t.clock);
  ASSERT_EQ(plant.configure(test::small_grasp()), HalStatus::ok);
  MockForceTorqueConfig c;
  c.force_noise_n = 0;
  c.torque_noise_nm = 0;
  // Sensor x along world y, sensor y along world -x.
  const double rotation[9] = {0, -1, 0, 1, 0, 0, 0, 0, 1};
  std::memcpy(c.rotation, rotation, sizeof rotation);
  c.load_n[2] = -0.5;
  c.lever_m[2] = -0.03;
  MockForceTorqueSensor ft(plant, t.clock, c);
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  plant.command_move(0.030, 0.01, 1000);  // 2 mm past contact at 32 mm
  t.step(500);
  WrenchReading w;
  ASSERT_EQ(ft.read(w), HalStatus::ok);
  const double f = plant.grip_force_n();
  EXPECT_NEAR(f, 4.0, 1e-9);
  EXPECT_NEAR(w.wrench[0], 0.0, 1e-12);
  EXPECT_NEAR(w.wrench[1], -f, 1e-12);
  EXPECT_NEAR(w.wrench[2], -0.5, 1e-12);
  // t = lever x F e_x = (0, 0, -0.03) x (F, 0, 0) = (0, -0.03 F, 0) in world; sensor x = world y.
  EXPECT_NEAR(w.wrench[3], -0.03 * f, 1e-12);
  EXPECT_NEAR(w.wrench[4], 0.0, 1e-12);
  EXPECT_EQ(w.header.status_bits, 0u);
  MockForceTorqueConfig bad;
  bad.rotation[0] = 2;
  MockForceTorqueSensor broken(plant, t.clock, bad);
  EXPECT_EQ(broken.configure(), HalStatus::invalid_argument);
}

TEST(HalMockForceTorque, BusOffAndEveryOtherFaultAreCountedExactly) {
  const FaultKind kinds[] = {FaultKind::drop,       FaultKind::freeze_data, FaultKind::freeze_stamp,
                             FaultKind::nan,        FaultKind::stamp_jump,  FaultKind::fault_bits,
                             FaultKind::disconnect, FaultKind::bus_off,     FaultKind::timeout};
  for (FaultKind kind : kinds) {
    SCOPED_TRACE(fault_kind_name(kind));
    SteppedClock t;
    SimulatedGrasp plant(t.clock);
    ASSERT_EQ(plant.configure(test::small_grasp()), HalStatus::ok);
    MockForceTorqueSensor ft(plant, t.clock);
    ASSERT_EQ(ft.configure(), HalStatus::ok);
    ASSERT_EQ(ft.start(), HalStatus::ok);
    FaultSchedule schedule;
    ASSERT_EQ(schedule.add(event(kind, 1.0205, 0.007, kind == FaultKind::stamp_jump ? -0.25 : kNaN)), HalStatus::ok);
    ASSERT_EQ(ft.set_fault_schedule(schedule), HalStatus::ok);
    WrenchReading w, before;
    int not_ok = 0;
    for (int k = 1; k <= 40; ++k) {
      t.step();
      const HalStatus s = ft.read(w);
      const bool inside = k >= 21 && k <= 27;
      if (k == 20) before = w;
      if (s != HalStatus::ok) {
        ++not_ok;
        EXPECT_TRUE(inside) << k;
        continue;
      }
      if (!inside) continue;
      if (kind == FaultKind::nan) {
        EXPECT_TRUE(std::isnan(w.wrench[0]) && std::isnan(w.wrench[5]));
      }
      if (kind == FaultKind::stamp_jump) {
        EXPECT_NEAR(w.header.stamp_s, t.now() - 0.25, 1e-12);
      }
      if (kind == FaultKind::fault_bits) {
        EXPECT_EQ(w.header.status_bits, kFtSupplyLow | kFtAnyError);
      }
      if (kind == FaultKind::freeze_data) {
        EXPECT_EQ(std::memcmp(w.wrench, before.wrench, sizeof w.wrench), 0);
      }
      if (kind == FaultKind::freeze_stamp) {
        EXPECT_EQ(w.header.stamp_s, before.header.stamp_s);
      }
    }
    const bool read_fault = kind == FaultKind::disconnect || kind == FaultKind::bus_off || kind == FaultKind::timeout;
    EXPECT_EQ(not_ok, read_fault || kind == FaultKind::drop ? 7 : 0);
    EXPECT_EQ(ft.fault_counters().of(kind), 7u);
    EXPECT_EQ(ft.fault_counters().total(), 7u);
    if (kind == FaultKind::bus_off) {
      EXPECT_EQ(ft.counters().bus_off, 7u);
    }
    if (kind == FaultKind::fault_bits) {
      EXPECT_EQ(ft.counters().fault_samples, 7u);
    }
  }
}

// --- particle observer -----------------------------------------------------------------------------

struct ObserverRig {
  SteppedClock t;
  SimulatedGrasp plant{t.clock};
  std::unique_ptr<MockParticleObserver> observer;
  explicit ObserverRig(const MockParticleObserverConfig& config) {
    EXPECT_EQ(plant.configure(test::small_grasp()), HalStatus::ok);
    observer = std::make_unique<MockParticleObserver>(plant, t.clock, config);
    EXPECT_EQ(observer->configure(), HalStatus::ok);
    EXPECT_EQ(observer->start(), HalStatus::ok);
  }
};

TEST(HalMockObserver, FramesAtCameraRateWithNoiseOfTheConfiguredSize) {
  MockParticleObserverConfig c;
  c.period_s = 0.032;  // a whole number of 1 ms ticks
  c.noise_m = 1e-4;
  ObserverRig rig(c);
  ParticleFrame f;
  int frames = 0;
  double sum = 0, sum_sq = 0;
  long values = 0;
  std::uint64_t last_sequence = 0;
  for (int k = 0; k <= 3200; ++k) {
    if (k > 0) rig.t.step();
    const HalStatus s = rig.observer->read(f);
    if (s == HalStatus::no_data) continue;
    ASSERT_EQ(s, HalStatus::ok);
    ++frames;
    EXPECT_EQ(f.header.sequence, last_sequence + 1);
    last_sequence = f.header.sequence;
    EXPECT_NEAR(f.header.stamp_s, 1.0 + 0.032 * static_cast<double>(f.header.sequence - 1), 1e-9);
    EXPECT_NEAR(f.header.stamp_s, rig.t.now(), 1e-9);
    ASSERT_EQ(f.particle_count, rig.plant.particle_count());
    EXPECT_EQ(f.dimension, 3);
    EXPECT_EQ(f.observed_count, f.particle_count);
    for (int i = 0; i < f.particle_count; ++i) {
      for (int d = 0; d < 3; ++d) {
        const double e = f.positions[3 * i + d] - rig.plant.positions()[i](d);
        sum += e;
        sum_sq += e * e;
        ++values;
      }
    }
  }
  EXPECT_EQ(frames, 101);
  const double mean = sum / static_cast<double>(values);
  const double sd = std::sqrt(sum_sq / static_cast<double>(values) - mean * mean);
  EXPECT_NEAR(mean, 0.0, 5e-6);
  EXPECT_NEAR(sd, 1e-4, 5e-6);
  EXPECT_EQ(rig.observer->counters().dropped, 0u);
}

TEST(HalMockObserver, LatencyDeliversTheCapturedStateLater) {
  MockParticleObserverConfig c;
  c.period_s = 0.010;
  c.latency_s = 0.025;
  c.noise_m = 0;
  ObserverRig rig(c);
  rig.plant.command_move(0.028, 0.02, 1000);
  ParticleFrame f;
  std::vector<double> captured_x;  // particle 0's true x at each capture
  int delivered = 0;
  for (int k = 0; k <= 200; ++k) {
    if (k > 0) rig.t.step();
    if (k % 10 == 0) captured_x.push_back(0);
    const HalStatus s = rig.observer->read(f);
    if (k % 10 == 0) captured_x.back() = rig.plant.positions()[0](0);
    if (s == HalStatus::no_data) continue;
    ASSERT_EQ(s, HalStatus::ok);
    ++delivered;
    const std::uint64_t index = f.header.sequence - 1;
    EXPECT_NEAR(f.header.stamp_s, 1.0 + 0.010 * static_cast<double>(index), 1e-9);
    EXPECT_NEAR(rig.t.now() - f.header.stamp_s, 0.025, 1e-9);
    EXPECT_EQ(f.positions[0], captured_x[index]);
  }
  EXPECT_EQ(delivered, 18);
}

TEST(HalMockObserver, OcclusionAndFrameFaults) {
  MockParticleObserverConfig c;
  c.period_s = 0.010;
  c.occlusion_fraction = 0.25;
  ObserverRig rig(c);
  ASSERT_EQ(rig.observer->add_fault(event(FaultKind::occlude, 1.0395, 0.020, 0.75)), HalStatus::ok);  // frames 4, 5
  ASSERT_EQ(rig.observer->add_fault(event(FaultKind::freeze_data, 1.0595, 0.020)), HalStatus::ok);    // frames 6, 7
  ASSERT_EQ(rig.observer->add_fault(event(FaultKind::nan, 1.0795, 0.010)), HalStatus::ok);            // frame 8
  ASSERT_EQ(rig.observer->add_fault(event(FaultKind::fault_bits, 1.0895, 0.010)), HalStatus::ok);     // frame 9
  ASSERT_EQ(rig.observer->add_fault(event(FaultKind::bus_off, 1, 1)), HalStatus::unsupported);
  const int n = rig.plant.particle_count();
  const int hidden = static_cast<int>(std::lround(0.25 * n));
  ParticleFrame f;
  std::vector<double> previous;
  for (int frame = 0; frame <= 11; ++frame) {
    if (frame > 0) rig.t.step(10);
    ASSERT_EQ(rig.observer->read(f), HalStatus::ok) << frame;
    const std::vector<double> now(f.positions, f.positions + 3 * n);
    int unobserved = 0;
    for (int i = 0; i < n; ++i) unobserved += std::isfinite(f.positions[3 * i]) ? 0 : 1;
    EXPECT_EQ(f.observed_count, n - unobserved);
    if (frame >= 4 && frame <= 7) {  // 6 and 7 repeat frame 5
      EXPECT_EQ(unobserved, static_cast<int>(std::lround(0.75 * n))) << frame;
    } else if (frame == 8) {
      EXPECT_EQ(unobserved, n);
    } else {
      EXPECT_EQ(unobserved, hidden) << frame;
    }
    if (frame == 6 || frame == 7) {
      EXPECT_EQ(std::memcmp(now.data(), previous.data(), now.size() * sizeof(double)), 0) << frame;
    } else if (frame > 0 && frame != 8 && frame != 9) {
      EXPECT_NE(std::memcmp(now.data(), previous.data(), now.size() * sizeof(double)), 0) << frame;
    }
    EXPECT_EQ((f.header.status_bits & kFrameDeviceFault) != 0, frame == 9) << frame;
    EXPECT_NE(f.header.status_bits & kFramePartial, 0u);
    // Hidden particles are those with the largest rest y.
    if (frame == 0) {
      for (int i = 0; i < n; ++i) {
        if (std::isfinite(f.positions[3 * i])) continue;
        for (int j = 0; j < n; ++j) {
          if (std::isfinite(f.positions[3 * j])) {
            EXPECT_GE(rig.plant.rest_positions()[i](1), rig.plant.rest_positions()[j](1));
          }
        }
      }
    }
    previous = now;
  }
  const FaultCounters& fc = rig.observer->fault_counters();
  EXPECT_EQ(fc.of(FaultKind::occlude), 2u);
  EXPECT_EQ(fc.of(FaultKind::freeze_data), 2u);
  EXPECT_EQ(fc.of(FaultKind::nan), 1u);
  EXPECT_EQ(fc.of(FaultKind::fault_bits), 1u);
  EXPECT_EQ(fc.total(), 6u);
  EXPECT_EQ(rig.observer->counters().fault_samples, 1u);
}

// --- cameras -------------------------------------------------------------------------------------------

TEST(HalMockCameras, ColourFramesChangeUnlessFrozen) {
  SteppedClock t;
  MockColorCameraConfig c;
  c.width = 16;
  c.height = 8;
  c.period_s = 0.010;
  MockColorCamera camera(t.clock, c);
  ColorFrame f;
  EXPECT_EQ(camera.read(f), HalStatus::wrong_state);
  ASSERT_EQ(camera.configure(), HalStatus::ok);
  ASSERT_EQ(camera.add_fault(event(FaultKind::nan, 1.0, 1.0)), HalStatus::unsupported);
  ASSERT_EQ(camera.add_fault(event(FaultKind::freeze_data, 1.0195, 0.010)), HalStatus::ok);  // frame 2
  ASSERT_EQ(camera.add_fault(event(FaultKind::drop, 1.0295, 0.010)), HalStatus::ok);         // frame 3
  ASSERT_EQ(camera.start(), HalStatus::ok);
  std::vector<std::uint8_t> previous;
  for (int frame = 0; frame <= 5; ++frame) {
    if (frame > 0) t.step(10);
    const HalStatus s = camera.read(f);
    if (frame == 3) {
      EXPECT_EQ(s, HalStatus::no_data);
      continue;
    }
    ASSERT_EQ(s, HalStatus::ok) << frame;
    EXPECT_EQ(f.width, 16);
    EXPECT_EQ(f.height, 8);
    EXPECT_EQ(f.stride_bytes, 48);
    EXPECT_EQ(f.format, PixelFormat::rgb8);
    EXPECT_EQ(f.header.sequence, static_cast<std::uint64_t>(frame + 1));
    const std::vector<std::uint8_t> now(f.data, f.data + 48 * 8);
    if (frame > 0) {
      EXPECT_EQ(now == previous, frame == 2) << frame;
    }
    previous = now;
  }
  EXPECT_EQ(camera.counters().dropped, 1u);
  EXPECT_EQ(camera.fault_counters().total(), 2u);
  MockColorCameraConfig bad;
  bad.width = 0;
  MockColorCamera broken(t.clock, bad);
  EXPECT_EQ(broken.configure(), HalStatus::invalid_argument);
}

TEST(HalMockCameras, DepthFramesHaveThePlaneAndNaNMeansNoMeasurement) {
  SteppedClock t;
  MockDepthCameraConfig c;
  c.width = 32;
  c.height = 24;
  c.period_s = 0.010;
  c.bump_height_m = 0;
  c.tilt_m_per_px = 0;
  MockDepthCamera camera(t.clock, c);
  ASSERT_EQ(camera.configure(), HalStatus::ok);
  ASSERT_EQ(camera.add_fault(event(FaultKind::nan, 1.0095, 0.010)), HalStatus::ok);              // frame 1
  ASSERT_EQ(camera.add_fault(event(FaultKind::stamp_jump, 1.0195, 0.010, 2.0)), HalStatus::ok);  // frame 2
  ASSERT_EQ(camera.start(), HalStatus::ok);
  DepthFrame f;
  ASSERT_EQ(camera.read(f), HalStatus::ok);
  EXPECT_EQ(f.stride_bytes, 64);
  EXPECT_EQ(f.depth_scale_m, 1e-3);
  EXPECT_TRUE(std::isfinite(f.fx) && f.fx > 0);
  for (int i = 0; i < 32 * 24; ++i) EXPECT_NEAR(f.data[i], 600, 2) << i;
  t.step(10);
  ASSERT_EQ(camera.read(f), HalStatus::ok);
  for (int i = 0; i < 32 * 24; ++i) EXPECT_EQ(f.data[i], 0) << i;
  t.step(10);
  ASSERT_EQ(camera.read(f), HalStatus::ok);
  EXPECT_NEAR(f.header.stamp_s, t.now() + 2.0, 1e-9);
  EXPECT_NEAR(f.data[5], 600, 2);
  EXPECT_EQ(camera.fault_counters().of(FaultKind::nan), 1u);
  EXPECT_EQ(camera.fault_counters().of(FaultKind::stamp_jump), 1u);
}

// --- the schedule itself -----------------------------------------------------------------------

TEST(HalFaultSchedule, ValidatesEventsAndOverlaps) {
  FaultSchedule s;
  EXPECT_EQ(s.add(event(FaultKind::drop, kNaN, 1)), HalStatus::invalid_argument);
  EXPECT_EQ(s.add(event(FaultKind::drop, 0, 0)), HalStatus::invalid_argument);
  EXPECT_EQ(s.add(event(FaultKind::drop, 0, std::numeric_limits<double>::infinity())), HalStatus::invalid_argument);
  EXPECT_EQ(s.add(event(static_cast<FaultKind>(40), 0, 1)), HalStatus::invalid_argument);
  EXPECT_EQ(s.add(event(FaultKind::fault_bits, 0, 1, 1.5)), HalStatus::invalid_argument);
  EXPECT_EQ(s.add(event(FaultKind::fault_bits, 0, 1, -1)), HalStatus::invalid_argument);
  EXPECT_EQ(s.add(event(FaultKind::occlude, 0, 1, 0)), HalStatus::invalid_argument);
  EXPECT_EQ(s.add(event(FaultKind::stamp_jump, 0, 1, std::numeric_limits<double>::infinity())),
            HalStatus::invalid_argument);
  EXPECT_EQ(s.size(), 0);
  EXPECT_EQ(s.add(event(FaultKind::stamp_jump, 1.0, 1.0, 0.1)), HalStatus::ok);
  EXPECT_EQ(s.add(event(FaultKind::stamp_jump, 1.5, 1.0, 0.2)), HalStatus::ok);
  EXPECT_EQ(s.add(event(FaultKind::nan, 1.5, 0.5)), HalStatus::ok);
  const ActiveFaults a = s.active_at(1.7);
  EXPECT_TRUE(a.has(FaultKind::stamp_jump) && a.has(FaultKind::nan));
  EXPECT_EQ(a.value[static_cast<int>(FaultKind::stamp_jump)], 0.1);     // the first added wins
  EXPECT_EQ(s.active_at(2.0).kinds, fault_bit(FaultKind::stamp_jump));  // [start, end)
  EXPECT_EQ(s.active_at(2.5).kinds, 0u);
  EXPECT_EQ(s.active_at(0.99).kinds, 0u);
  EXPECT_EQ(s.kinds(), fault_bit(FaultKind::stamp_jump) | fault_bit(FaultKind::nan));
  while (s.size() < kFaultCapacity) ASSERT_EQ(s.add(event(FaultKind::drop, 9, 1)), HalStatus::ok);
  EXPECT_EQ(s.add(event(FaultKind::drop, 9, 1)), HalStatus::capacity_exceeded);
  FaultKind k = FaultKind::drop;
  EXPECT_TRUE(parse_fault_kind("bus_off", 7, k));
  EXPECT_EQ(k, FaultKind::bus_off);
  EXPECT_FALSE(parse_fault_kind("bus_of", 6, k));
  EXPECT_FALSE(parse_fault_kind(nullptr, 0, k));
  for (int i = 0; i < kFaultKindCount; ++i) {
    const char* name = fault_kind_name(static_cast<FaultKind>(i));
    ASSERT_TRUE(parse_fault_kind(name, std::strlen(name), k));
    EXPECT_EQ(static_cast<int>(k), i);
  }
}

// A clock years ahead of the start: reads stay bounded and defined (no sample index cast
// beyond 2^53, the plant skips the gap and counts it).
TEST(HalMockGripper, AClockFarAheadIsBoundedAndDefined) {
  GripperRig rig;
  GripperReading r;
  ASSERT_EQ(rig.t.clock.set(1e18), HalStatus::ok);
  EXPECT_EQ(rig.gripper.read(r), HalStatus::no_data);
  EXPECT_EQ(rig.plant.counters().periods, static_cast<std::uint64_t>(rig.plant.config().max_catch_up_periods));
  EXPECT_GT(rig.plant.counters().skipped_periods, 0u);
  EXPECT_EQ(rig.gripper.move_to(0.03, 0.01, 10), HalStatus::ok);
}

}  // namespace
}  // namespace pliant::hal
