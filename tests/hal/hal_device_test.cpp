// The HAL's own machinery: clocks, the device lifecycle and counters, the stream monitor and
// the conversion of reads into grasp-guard samples.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "hal_fixture.hpp"
#include "pliant/hal/guard_inputs.hpp"
#include "pliant/hal/stream_monitor.hpp"

namespace pliant::hal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// --- clocks ----------------------------------------------------------------------------------

TEST(HalClock, ManualClockMovesOnlyForward) {
  ManualClock clock(2.5);
  EXPECT_EQ(clock.now_s(), 2.5);
  EXPECT_EQ(clock.advance(0.5), HalStatus::ok);
  EXPECT_EQ(clock.now_s(), 3.0);
  EXPECT_EQ(clock.advance(-0.1), HalStatus::invalid_argument);
  EXPECT_EQ(clock.advance(kNaN), HalStatus::invalid_argument);
  EXPECT_EQ(clock.set(2.9), HalStatus::invalid_argument);
  EXPECT_EQ(clock.set(std::numeric_limits<double>::infinity()), HalStatus::invalid_argument);
  EXPECT_EQ(clock.now_s(), 3.0);
  EXPECT_EQ(clock.set(3.0), HalStatus::ok);
  EXPECT_EQ(clock.set(7.0), HalStatus::ok);
  EXPECT_EQ(clock.now_s(), 7.0);
  EXPECT_EQ(ManualClock(kNaN).now_s(), 0.0);
}

TEST(HalClock, SteadyClockIsMonotonic) {
  SteadyClock clock;
  double previous = clock.now_s();
  for (int i = 0; i < 1000; ++i) {
    const double now = clock.now_s();
    ASSERT_GE(now, previous);
    previous = now;
  }
  EXPECT_TRUE(std::isfinite(previous));
}

// --- lifecycle and counters, on a scripted device ----------------------------------------------

/// A sensor that answers each read with the next scripted (status, sequence, status bits).
class ScriptedSensor final : public ForceTorqueSensor {
 public:
  struct Answer {
    HalStatus status;
    std::uint64_t sequence;
    std::uint32_t bits;
  };
  std::vector<Answer> answers;
  std::size_t next = 0;
  HalStatus configure_result = HalStatus::ok;
  int configures = 0, starts = 0, stops = 0, cleanups = 0;

 protected:
  HalStatus on_configure() override {
    ++configures;
    return configure_result;
  }
  HalStatus on_start() noexcept override {
    ++starts;
    return HalStatus::ok;
  }
  HalStatus on_stop() noexcept override {
    ++stops;
    return HalStatus::ok;
  }
  HalStatus on_cleanup() noexcept override {
    ++cleanups;
    return HalStatus::ok;
  }
  HalStatus on_read(WrenchReading& out) noexcept override {
    if (next >= answers.size()) return HalStatus::no_data;
    const Answer a = answers[next++];
    out.header.stamp_s = static_cast<double>(a.sequence);
    out.header.sequence = a.sequence;
    out.header.status_bits = a.bits;
    for (double& v : out.wrench) v = 1.0;
    return a.status;
  }
};

TEST(HalDevice, LifecycleRefusesCallsInTheWrongStateAndCountsThem) {
  ScriptedSensor s;
  WrenchReading r;
  EXPECT_EQ(s.state(), LifecycleState::unconfigured);
  EXPECT_EQ(s.read(r), HalStatus::wrong_state);  // before configure
  EXPECT_EQ(s.start(), HalStatus::wrong_state);
  EXPECT_EQ(s.stop(), HalStatus::wrong_state);
  EXPECT_EQ(s.cleanup(), HalStatus::wrong_state);
  EXPECT_EQ(s.configure(), HalStatus::ok);  // resets the counters
  EXPECT_EQ(s.counters().lifecycle_errors, 0u);
  EXPECT_EQ(s.state(), LifecycleState::inactive);
  EXPECT_EQ(s.read(r), HalStatus::wrong_state);  // before start
  EXPECT_EQ(s.configure(), HalStatus::wrong_state);
  EXPECT_EQ(s.counters().lifecycle_errors, 2u);
  EXPECT_EQ(s.counters().reads, 0u);
  EXPECT_EQ(s.start(), HalStatus::ok);
  EXPECT_EQ(s.state(), LifecycleState::active);
  EXPECT_EQ(s.start(), HalStatus::wrong_state);
  EXPECT_EQ(s.read(r), HalStatus::no_data);
  EXPECT_EQ(s.counters().reads, 1u);
  EXPECT_EQ(s.counters().no_data, 1u);
  EXPECT_EQ(s.cleanup(), HalStatus::wrong_state);
  EXPECT_EQ(s.stop(), HalStatus::ok);
  EXPECT_EQ(s.read(r), HalStatus::wrong_state);  // after stop
  EXPECT_EQ(s.cleanup(), HalStatus::ok);
  EXPECT_EQ(s.state(), LifecycleState::unconfigured);
  EXPECT_EQ(s.counters().lifecycle_errors, 5u);
  EXPECT_EQ(s.configures, 1);
  EXPECT_EQ(s.starts, 1);
  EXPECT_EQ(s.stops, 1);
  EXPECT_EQ(s.cleanups, 1);
}

TEST(HalDevice, FailedConfigureLeavesTheDeviceUnconfigured) {
  ScriptedSensor s;
  s.configure_result = HalStatus::invalid_argument;
  EXPECT_EQ(s.configure(), HalStatus::invalid_argument);
  EXPECT_EQ(s.state(), LifecycleState::unconfigured);
  EXPECT_EQ(s.start(), HalStatus::wrong_state);
  s.configure_result = HalStatus::ok;
  EXPECT_EQ(s.configure(), HalStatus::ok);
  EXPECT_EQ(s.state(), LifecycleState::inactive);
}

TEST(HalDevice, CountsDropsFaultsAndReconnects) {
  ScriptedSensor s;
  const ScriptedSensor::Answer script[] = {
      {HalStatus::ok, 1, 0},
      {HalStatus::ok, 2, 0},
      {HalStatus::ok, 5, 0},               // 3 and 4 dropped
      {HalStatus::ok, 6, kFtSupplyLow},    // a fault sample
      {HalStatus::ok, 7, kFtCanBusError},  // degraded, not in the fault mask
      {HalStatus::timeout, 0, 0},
      {HalStatus::bus_off, 0, 0},
      {HalStatus::disconnected, 0, 0},
      {HalStatus::disconnected, 0, 0},
      {HalStatus::no_data, 0, 0},  // not proof of a reconnect (may be a driver's back-off)
      {HalStatus::ok, 8, 0},       // back: a reconnect
      {HalStatus::io_error, 0, 0},
      {HalStatus::device_fault, 0, 0},
      {HalStatus::disconnected, 0, 0},
      {HalStatus::ok, 12, 0},  // a second outage; 9-11 lost
  };
  for (const ScriptedSensor::Answer& a : script) s.answers.push_back(a);
  ASSERT_EQ(s.configure(), HalStatus::ok);
  ASSERT_EQ(s.start(), HalStatus::ok);
  WrenchReading r;
  std::uint64_t last_delivered = 0;
  for (std::size_t i = 0; i < s.answers.size(); ++i) {
    const HalStatus status = s.read(r);
    EXPECT_EQ(status, s.answers[i].status) << i;
    if (status == HalStatus::ok) last_delivered = r.header.sequence;
  }
  EXPECT_EQ(last_delivered, 12u);
  const DeviceCounters& c = s.counters();
  EXPECT_EQ(c.reads, s.answers.size());
  EXPECT_EQ(c.samples, 7u);
  EXPECT_EQ(c.no_data, 1u);
  EXPECT_EQ(c.dropped, 2u + 3u);
  EXPECT_EQ(c.fault_samples, 1u);
  EXPECT_EQ(c.timeouts, 1u);
  EXPECT_EQ(c.bus_off, 1u);
  EXPECT_EQ(c.disconnected, 3u);
  EXPECT_EQ(c.disconnects, 2u);
  EXPECT_EQ(c.reconnects, 2u);
  EXPECT_EQ(c.io_errors, 1u);
  EXPECT_EQ(c.device_faults, 1u);
  EXPECT_EQ(c.faults(), 7u);
}

TEST(HalDevice, FailedReadLeavesTheCallersSampleUntouched) {
  ScriptedSensor s;
  for (const ScriptedSensor::Answer& a :
       {ScriptedSensor::Answer{HalStatus::ok, 1, 0}, ScriptedSensor::Answer{HalStatus::timeout, 9, 0}}) {
    s.answers.push_back(a);
  }
  ASSERT_EQ(s.configure(), HalStatus::ok);
  ASSERT_EQ(s.start(), HalStatus::ok);
  WrenchReading r;
  ASSERT_EQ(s.read(r), HalStatus::ok);
  EXPECT_EQ(s.read(r), HalStatus::timeout);
  EXPECT_EQ(r.header.sequence, 1u);
  EXPECT_EQ(s.read(r), HalStatus::no_data);
  EXPECT_EQ(r.header.sequence, 1u);
}

TEST(HalDevice, StatusAndStateNames) {
  EXPECT_STREQ(hal_status_name(HalStatus::bus_off), "bus_off");
  EXPECT_STREQ(hal_status_name(HalStatus::no_data), "no_data");
  EXPECT_STREQ(hal_status_name(static_cast<HalStatus>(200)), "unknown");
  EXPECT_STREQ(lifecycle_state_name(LifecycleState::active), "active");
  EXPECT_TRUE(is_fault(HalStatus::timeout));
  EXPECT_FALSE(is_fault(HalStatus::no_data));
  EXPECT_FALSE(is_fault(HalStatus::wrong_state));
  EXPECT_EQ(gripper_fault_code(0x0e00u | kGripperActivated), kGripperFaultOverCurrent);
}

// --- stream monitor ----------------------------------------------------------------------------

SampleHeader header(std::uint64_t sequence, double stamp) {
  SampleHeader h;
  h.sequence = sequence;
  h.stamp_s = stamp;
  return h;
}

TEST(HalStreamMonitor, FlagsEachStreamFaultOnTheSampleThatShowsIt) {
  StreamMonitor m;
  StreamMonitorConfig config;
  config.max_interval_s = 0.0035;
  ASSERT_EQ(m.configure(config), HalStatus::ok);
  double v[2] = {1.0, 2.0};
  EXPECT_EQ(m.check(header(1, 1.000), v, 2), 0u);
  v[0] = 1.1;
  EXPECT_EQ(m.check(header(2, 1.001), v, 2), 0u);
  v[0] = 1.2;
  EXPECT_EQ(m.check(header(5, 1.004), v, 2), kStreamSequenceGap);  // 3, 4 dropped; 3 ms step
  EXPECT_EQ(m.check(header(6, 1.004), v, 2) & (kStreamStampStall | kStreamFrozen), kStreamStampStall | kStreamFrozen);
  v[0] = 1.3;
  EXPECT_EQ(m.check(header(7, 1.003), v, 2), kStreamStampBackwards);
  v[0] = 1.4;
  EXPECT_EQ(m.check(header(8, 1.010), v, 2), kStreamStampJump);  // 7 ms > 3.5 ms
  v[1] = kNaN;
  EXPECT_EQ(m.check(header(9, 1.011), v, 2), kStreamNonFinite);
  v[1] = 2.0;
  v[0] = 1.5;
  EXPECT_EQ(m.check(header(10, kNaN), v, 2), kStreamNonFinite);
  v[0] = 1.6;
  EXPECT_EQ(m.check(header(11, 1.012), v, 2), 0u);
  const StreamMonitorCounters& c = m.counters();
  EXPECT_EQ(c.samples, 9u);
  EXPECT_EQ(c.gaps, 1u);
  EXPECT_EQ(c.dropped, 2u);
  EXPECT_EQ(c.stalls, 1u);
  EXPECT_EQ(c.frozen, 1u);
  EXPECT_EQ(c.backwards, 1u);
  EXPECT_EQ(c.jumps, 1u);
  EXPECT_EQ(c.non_finite, 2u);
  EXPECT_EQ(c.flagged, 5u);
}

TEST(HalStreamMonitor, FrozenAfterTheConfiguredRepeatsAndNaNFraction) {
  StreamMonitor m;
  StreamMonitorConfig config;
  config.frozen_repeats = 2;
  config.max_non_finite_fraction = 0.5;
  ASSERT_EQ(m.configure(config), HalStatus::ok);
  double v[4] = {1, 2, kNaN, kNaN};  // half unobserved: allowed
  EXPECT_EQ(m.check(header(1, 1.0), v, 4), 0u);
  EXPECT_EQ(m.check(header(2, 1.1), v, 4), 0u);             // first repeat
  EXPECT_EQ(m.check(header(3, 1.2), v, 4), kStreamFrozen);  // second
  v[1] = kNaN;                                              // three of four
  EXPECT_EQ(m.check(header(4, 1.3), v, 4), kStreamNonFinite);
  config.frozen_repeats = 0;  // off
  ASSERT_EQ(m.configure(config), HalStatus::ok);
  EXPECT_EQ(m.check(header(5, 1.4), v, 4) & kStreamFrozen, 0u);
  EXPECT_EQ(m.check(header(6, 1.5), v, 4) & kStreamFrozen, 0u);
  EXPECT_EQ(m.check(header(7, 1.6), nullptr, 0), 0u);  // no payload
}

TEST(HalStreamMonitor, RefusesBadConfiguration) {
  StreamMonitor m;
  StreamMonitorConfig bad;
  bad.max_interval_s = 0;
  EXPECT_EQ(m.configure(bad), HalStatus::invalid_argument);
  bad = StreamMonitorConfig{};
  bad.max_interval_s = kNaN;
  EXPECT_EQ(m.configure(bad), HalStatus::invalid_argument);
  bad = StreamMonitorConfig{};
  bad.frozen_repeats = -1;
  EXPECT_EQ(m.configure(bad), HalStatus::invalid_argument);
  bad = StreamMonitorConfig{};
  bad.max_non_finite_fraction = 1.5;
  EXPECT_EQ(m.configure(bad), HalStatus::invalid_argument);
  EXPECT_TRUE(std::isinf(m.config().max_interval_s));  // unchanged
}

// --- guard inputs ---------------------------------------------------------------------------------

TEST(HalGuardInputs, ReadsBecomeGuardSamples) {
  GripperSample g;
  GripperReading r;
  r.header.stamp_s = 2.0;
  r.header.status_bits = kGripperActivated;
  r.width_m = 0.03;
  r.force_n = 1.5;
  r.current_a = 0.2;
  update_gripper_sample(HalStatus::ok, r, kStreamFrozen, g);
  EXPECT_TRUE(g.valid);
  EXPECT_EQ(g.stamp_s, 2.0);
  EXPECT_EQ(g.width_m, 0.03);
  EXPECT_EQ(g.force_n, 1.5);
  EXPECT_EQ(g.current_a, 0.2);
  EXPECT_EQ(g.status_bits, kGripperActivated | kStreamFrozen);
  // A Modbus timeout: the previous values with the flag, so the guard ages and refuses them.
  update_gripper_sample(HalStatus::timeout, GripperReading{}, 0, g);
  EXPECT_TRUE(g.timeout);
  EXPECT_TRUE(g.valid);
  EXPECT_EQ(g.stamp_s, 2.0);
  update_gripper_sample(HalStatus::no_data, GripperReading{}, 0, g);
  EXPECT_FALSE(g.timeout);
  EXPECT_EQ(g.width_m, 0.03);
  update_gripper_sample(HalStatus::disconnected, GripperReading{}, 0, g);
  EXPECT_FALSE(g.valid);
  update_gripper_sample(HalStatus::ok, r, 0, g);
  EXPECT_TRUE(g.valid);
  EXPECT_FALSE(g.timeout);

  WrenchSample w;
  WrenchReading wr;
  wr.header.stamp_s = 3.0;
  wr.header.status_bits = kFtSupplyLow;
  for (int d = 0; d < 6; ++d) wr.wrench[d] = d;
  update_wrench_sample(HalStatus::ok, wr, 0, w);
  EXPECT_TRUE(w.valid);
  EXPECT_EQ(w.wrench[5], 5.0);
  EXPECT_EQ(w.status_bits, kFtSupplyLow);
  update_wrench_sample(HalStatus::bus_off, WrenchReading{}, 0, w);
  EXPECT_TRUE(w.bus_off);
  EXPECT_EQ(w.wrench[5], 5.0);
  update_wrench_sample(HalStatus::io_error, WrenchReading{}, 0, w);
  EXPECT_FALSE(w.valid);

  DeformationSample d;
  update_deformation_sample(HalStatus::ok, 4.0, 0.02, kFramePartial, d);
  EXPECT_TRUE(d.valid);
  EXPECT_EQ(d.strain, 0.02);
  EXPECT_EQ(d.status_bits, kFramePartial);
  update_deformation_sample(HalStatus::timeout, kNaN, kNaN, 0, d);
  EXPECT_TRUE(d.timeout);
  EXPECT_EQ(d.strain, 0.02);
}

// The small grasp on a stepped clock and a grasp guard with its default masks on the plant's
// model (squeezed along x), with a coarse prediction grid to keep the tests fast.
struct GuardedPlant {
  test::SteppedClock t;
  SimulatedGrasp plant{t.clock};
  GraspGuardConfig config;
  std::vector<unsigned char> block;
  GraspGuard<3, double> guard;
  Status status = Status::not_initialized;
  GuardedPlant() {
    if (plant.configure(test::small_grasp()) != HalStatus::ok) return;
    config.prediction_beta_points = 3;
    config.prediction_closure_points = 4;
    block.resize(grasp_guard_workspace_size(plant.model(), config));
    Arena arena(block.data(), block.size());
    GraspObject<3, double> object;
    object.squeeze_axis = Eigen::Vector3d(1, 0, 0);
    status = grasp_guard_init(arena, plant.model(), object, config, guard);
  }
};

// The conversions feed the guard: a bus-off read makes its verdict not ok in that cycle.
TEST(HalGuardInputs, BusOffReachesTheGuardInTheSameCycle) {
  GuardedPlant rig;
  ASSERT_EQ(rig.status, Status::ok);
  test::SteppedClock& t = rig.t;
  SimulatedGrasp& plant = rig.plant;
  GraspGuard<3, double>& guard = rig.guard;
  MockForceTorqueSensor ft(plant, t.clock);
  MockGripper gripper(plant, t.clock);
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(gripper.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  ASSERT_EQ(gripper.start(), HalStatus::ok);
  ASSERT_EQ(ft.add_fault(test::event(FaultKind::bus_off, 1.0105, 0.005)), HalStatus::ok);
  GraspGuardInput in;
  in.deformation.valid = true;
  in.deformation.strain = 0;
  in.estimate.valid = true;
  in.estimate.msm_beta = 0.5;
  in.estimate.msm_beta_std = 0.01;
  GraspGuardOutput out;
  for (int k = 0; k < 20; ++k) {
    t.step();
    in.now_s = t.now();
    in.deformation.stamp_s = in.estimate.stamp_s = t.now();
    GripperReading g;
    update_gripper_sample(gripper.read(g), g, 0, in.gripper);
    WrenchReading w;
    const HalStatus s = ft.read(w);
    update_wrench_sample(s, w, 0, in.wrench);
    ASSERT_EQ(grasp_guard_update(guard, in, out), Status::ok);
    if (s == HalStatus::bus_off) {
      EXPECT_NE(out.verdict, GraspVerdict::ok) << k;
      EXPECT_EQ(out.reason, GuardReason::bus_off) << k;
    } else if (k < 10) {
      EXPECT_EQ(out.verdict, GraspVerdict::ok) << k << " " << guard_reason_name(out.reason);
    }
  }
  EXPECT_EQ(ft.fault_counters().of(FaultKind::bus_off), 5u);
  EXPECT_EQ(ft.counters().bus_off, 5u);
}

// The mock gripper with the guard's default masks: closing on the plant (activated, moving,
// then object detected) is never a fault; the fault code the mock reports during a fault_bits
// event is, in the cycle it arrives, and the verdict clears after it.
TEST(HalGuardInputs, TheDefaultMaskReadsTheMockGrippersStatesAndFaults) {
  GuardedPlant rig;
  ASSERT_EQ(rig.status, Status::ok);
  test::SteppedClock& t = rig.t;
  SimulatedGrasp& plant = rig.plant;
  GraspGuard<3, double>& guard = rig.guard;
  const GraspGuardConfig& config = rig.config;
  MockGripper gripper(plant, t.clock);
  ASSERT_EQ(gripper.configure(), HalStatus::ok);
  ASSERT_EQ(gripper.start(), HalStatus::ok);
  ASSERT_EQ(gripper.add_fault(test::event(FaultKind::fault_bits, 1.0305, 0.005)), HalStatus::ok);
  GripperCommand close;
  close.kind = GripperCommandKind::move;
  close.width_m = 0.0;
  close.speed_m_per_s = 0.02;
  close.force_n = 5.0;
  ASSERT_EQ(gripper.write(close), HalStatus::ok);
  GraspGuardInput in;
  in.wrench.valid = in.deformation.valid = in.estimate.valid = true;
  for (double& w : in.wrench.wrench) w = 0;
  in.deformation.strain = 0;
  in.estimate.msm_beta = 0.5;
  in.estimate.msm_beta_std = 0.01;
  GraspGuardOutput out;
  std::uint32_t states_seen = 0;
  int faulted_cycles = 0;
  int clean_after_fault = 0;
  for (int k = 0; k < 60; ++k) {
    t.step();
    in.now_s = in.wrench.stamp_s = in.deformation.stamp_s = in.estimate.stamp_s = t.now();
    GripperReading g;
    ASSERT_EQ(gripper.read(g), HalStatus::ok) << k;
    update_gripper_sample(HalStatus::ok, g, 0, in.gripper);
    ASSERT_EQ(grasp_guard_update(guard, in, out), Status::ok);
    const bool faulted = gripper_fault_code(g.header.status_bits) != 0;
    states_seen |= g.header.status_bits & 0x0fu;
    faulted_cycles += faulted ? 1 : 0;
    const bool gripper_fault = (out.fault_sources & (1u << static_cast<unsigned>(GuardSource::gripper))) != 0;
    // Before the fault and once the latch has seen clear_samples clean samples after it: no
    // gripper fault; during it: a sensor fault in every cycle.
    const bool latched = faulted_cycles > 0 && clean_after_fault < config.clear_samples;
    if (faulted) {
      EXPECT_TRUE(gripper_fault) << k;
      EXPECT_EQ(out.reason, GuardReason::sensor_fault) << k;
    } else if (!latched) {
      EXPECT_FALSE(gripper_fault) << k << " status " << g.header.status_bits << " " << guard_reason_name(out.reason);
    }
    clean_after_fault = faulted ? 0 : clean_after_fault + (faulted_cycles > 0 ? 1 : 0);
  }
  EXPECT_EQ(faulted_cycles, 5);
  EXPECT_NE(states_seen & kGripperActivated, 0u);
  EXPECT_NE(states_seen & kGripperMoving, 0u);
}

}  // namespace
}  // namespace pliant::hal
