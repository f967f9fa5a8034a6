// Replay devices (hal/mock/replay_devices.hpp): recorded samples come back with the recorded
// values and spacing, in real time or stepped, with sequence gaps when read too slowly, a clean
// end of stream, pause on stop/start, every fault kind, and malformed channels refused.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "pliant/hal/mock/replay_devices.hpp"

namespace pliant::hal {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// 11 wrench samples at 10 ms from t = 5 s, Fz = k.
RecordedChannel wrench_channel() {
  RecordedChannel c;
  c.width = 6;
  for (int k = 0; k <= 10; ++k) {
    c.t_s.push_back(5.0 + 0.01 * k);
    for (int a = 0; a < 6; ++a) c.values.push_back(a == 2 ? k : 0.1 * a);
  }
  return c;
}

TEST(HalReplay, StepsThroughEverySampleWithRecordedSpacing) {
  const RecordedChannel c = wrench_channel();
  ManualClock clock(100.0);
  ReplayForceTorque ft(c, clock, ReplayTiming{ReplayMode::stepped, 1.0});
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  WrenchReading r;
  for (int k = 0; k <= 10; ++k) {
    ASSERT_EQ(ft.read(r), HalStatus::ok) << k;
    EXPECT_EQ(r.wrench[2], k);
    EXPECT_DOUBLE_EQ(r.wrench[1], 0.1);
    EXPECT_EQ(r.header.sequence, static_cast<std::uint64_t>(k + 1));
    EXPECT_NEAR(r.header.stamp_s, 100.0 + 0.01 * k, 1e-9);
  }
  EXPECT_TRUE(ft.finished());
  EXPECT_EQ(ft.read(r), HalStatus::no_data);
  EXPECT_EQ(ft.counters().samples, 11u);
  EXPECT_EQ(ft.counters().dropped, 0u);
}

TEST(HalReplay, RealTimeDeliversWhatIsDueAndCountsWhatWasMissed) {
  const RecordedChannel c = wrench_channel();
  ManualClock clock(1.0);
  ReplayForceTorque ft(c, clock, ReplayTiming{ReplayMode::realtime, 2.0});  // twice as fast
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  WrenchReading r;
  ASSERT_EQ(ft.read(r), HalStatus::ok);  // sample 0 is due at start
  EXPECT_EQ(r.wrench[2], 0);
  EXPECT_EQ(ft.read(r), HalStatus::no_data);
  ASSERT_EQ(clock.advance(0.0049), HalStatus::ok);
  EXPECT_EQ(ft.read(r), HalStatus::no_data);  // sample 1 due at 1.005
  ASSERT_EQ(clock.advance(0.0001), HalStatus::ok);
  ASSERT_EQ(ft.read(r), HalStatus::ok);
  EXPECT_EQ(r.wrench[2], 1);
  EXPECT_NEAR(r.header.stamp_s, 1.005, 1e-12);
  ASSERT_EQ(clock.advance(0.0175), HalStatus::ok);  // t = 1.0225: samples 2..4 due, 4 the newest
  ASSERT_EQ(ft.read(r), HalStatus::ok);
  EXPECT_EQ(r.wrench[2], 4);
  EXPECT_EQ(r.header.sequence, 5u);
  EXPECT_EQ(ft.counters().dropped, 2u);
  ASSERT_EQ(clock.advance(1.0), HalStatus::ok);
  ASSERT_EQ(ft.read(r), HalStatus::ok);
  EXPECT_EQ(r.wrench[2], 10);
  EXPECT_TRUE(ft.finished());
  EXPECT_EQ(ft.read(r), HalStatus::no_data);
}

TEST(HalReplay, StopAndStartPausesThePlayback) {
  const RecordedChannel c = wrench_channel();
  ManualClock clock(0.0);
  ReplayForceTorque ft(c, clock);
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  WrenchReading r;
  ASSERT_EQ(ft.read(r), HalStatus::ok);
  ASSERT_EQ(ft.stop(), HalStatus::ok);
  ASSERT_EQ(clock.advance(30.0), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  ASSERT_EQ(ft.read(r), HalStatus::ok);  // the next sample is due at the restart, none skipped
  EXPECT_EQ(r.wrench[2], 1);
  EXPECT_NEAR(r.header.stamp_s, 30.0, 1e-12);
  EXPECT_EQ(ft.counters().dropped, 0u);
}

TEST(HalReplay, FaultsAreInjectedAndCounted) {
  const RecordedChannel c = wrench_channel();
  ManualClock clock(0.0);
  ReplayForceTorque ft(c, clock, ReplayTiming{ReplayMode::stepped, 1.0});
  // Stamps are 0, 0.01, ... 0.10.
  ASSERT_EQ(ft.add_fault({0.005, 0.01, FaultKind::drop, kNaN}), HalStatus::ok);          // sample 1
  ASSERT_EQ(ft.add_fault({0.015, 0.01, FaultKind::freeze_data, kNaN}), HalStatus::ok);   // sample 2
  ASSERT_EQ(ft.add_fault({0.025, 0.01, FaultKind::nan, kNaN}), HalStatus::ok);           // sample 3
  ASSERT_EQ(ft.add_fault({0.035, 0.01, FaultKind::stamp_jump, -0.25}), HalStatus::ok);   // sample 4
  ASSERT_EQ(ft.add_fault({0.045, 0.01, FaultKind::fault_bits, 64}), HalStatus::ok);      // sample 5
  ASSERT_EQ(ft.add_fault({0.055, 0.01, FaultKind::freeze_stamp, kNaN}), HalStatus::ok);  // sample 6
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  WrenchReading r;
  ASSERT_EQ(ft.read(r), HalStatus::ok);
  EXPECT_EQ(r.wrench[2], 0);
  EXPECT_EQ(ft.read(r), HalStatus::no_data);  // sample 1 dropped
  ASSERT_EQ(ft.read(r), HalStatus::ok);       // sample 2 frozen on sample 0's values
  EXPECT_EQ(r.wrench[2], 0);
  EXPECT_EQ(r.header.sequence, 3u);
  ASSERT_EQ(ft.read(r), HalStatus::ok);
  EXPECT_TRUE(std::isnan(r.wrench[2]));
  ASSERT_EQ(ft.read(r), HalStatus::ok);
  EXPECT_NEAR(r.header.stamp_s, 0.04 - 0.25, 1e-12);
  ASSERT_EQ(ft.read(r), HalStatus::ok);
  EXPECT_EQ(r.header.status_bits, 64u);
  const double stamp5 = r.header.stamp_s;
  ASSERT_EQ(ft.read(r), HalStatus::ok);  // sample 6 re-sends sample 5, stamp included
  EXPECT_EQ(r.header.stamp_s, stamp5);
  EXPECT_EQ(r.wrench[2], 5);
  EXPECT_EQ(r.header.sequence, 7u);
  const FaultCounters& f = ft.fault_counters();
  for (FaultKind k : {FaultKind::drop, FaultKind::freeze_data, FaultKind::nan, FaultKind::stamp_jump,
                      FaultKind::fault_bits, FaultKind::freeze_stamp}) {
    EXPECT_EQ(f.of(k), 1u) << fault_kind_name(k);
  }
  EXPECT_EQ(ft.counters().dropped, 1u);
  // Bit 6 is kFtBadCalibration: sample 5, and sample 6 that re-sent it.
  EXPECT_EQ(ft.counters().fault_samples, 2u);
}

TEST(HalReplay, ReadFaultsComeFromTheClockOfTheRead) {
  const RecordedChannel c = wrench_channel();
  ManualClock clock(0.0);
  ReplayForceTorque ft(c, clock, ReplayTiming{ReplayMode::stepped, 1.0});
  ASSERT_EQ(ft.add_fault({1.0, 1.0, FaultKind::bus_off, kNaN}), HalStatus::ok);
  ASSERT_EQ(ft.add_fault({2.0, 1.0, FaultKind::disconnect, kNaN}), HalStatus::ok);
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  WrenchReading r;
  ASSERT_EQ(ft.read(r), HalStatus::ok);
  ASSERT_EQ(clock.set(1.5), HalStatus::ok);
  EXPECT_EQ(ft.read(r), HalStatus::bus_off);
  ASSERT_EQ(clock.set(2.5), HalStatus::ok);
  EXPECT_EQ(ft.read(r), HalStatus::disconnected);
  ASSERT_EQ(clock.set(3.5), HalStatus::ok);
  ASSERT_EQ(ft.read(r), HalStatus::ok);  // recovered: the next sample, nothing lost while stepped
  EXPECT_EQ(r.wrench[2], 1);
  EXPECT_EQ(ft.counters().bus_off, 1u);
  EXPECT_EQ(ft.counters().disconnects, 1u);
  EXPECT_EQ(ft.counters().reconnects, 1u);
}

TEST(HalReplay, GripperReplaysAndRefusesCommands) {
  RecordedChannel c;
  c.width = 2;
  c.t_s = {0.0, 0.1, 0.2};
  c.values = {0.05, kNaN, 0.04, 1.5, 0.03, 3.0};
  ManualClock clock(0.0);
  ReplayGripper g(c, clock, ReplayTiming{ReplayMode::stepped, 1.0});
  ASSERT_EQ(g.configure(), HalStatus::ok);
  EXPECT_DOUBLE_EQ(g.limits().max_width_m, 0.05);
  ASSERT_EQ(g.start(), HalStatus::ok);
  GripperReading r;
  ASSERT_EQ(g.read(r), HalStatus::ok);
  EXPECT_DOUBLE_EQ(r.width_m, 0.05);
  EXPECT_TRUE(std::isnan(r.force_n));
  EXPECT_EQ(r.header.status_bits, kGripperActivated);
  ASSERT_EQ(g.read(r), HalStatus::ok);
  EXPECT_DOUBLE_EQ(r.force_n, 1.5);
  EXPECT_EQ(g.move_to(0.01, 0.01, 5), HalStatus::unsupported);
  EXPECT_EQ(g.counters().rejected_writes, 1u);
}

TEST(HalReplay, ObserverOccludesTheTopParticles) {
  // Three 2D particles at y = 0, 2, 1; two frames.
  RecordedChannel c;
  c.width = 6;
  c.t_s = {0.0, 0.1};
  c.values = {0, 0, 1, 2, 2, 1, 0, 0.1, 1, 2.1, 2, kNaN};
  ManualClock clock(0.0);
  ReplayParticleObserver o(c, 2, clock, ReplayTiming{ReplayMode::stepped, 1.0});
  ASSERT_EQ(o.add_fault({0.05, 1.0, FaultKind::occlude, 0.34}), HalStatus::ok);  // one of three
  ASSERT_EQ(o.configure(), HalStatus::ok);
  ASSERT_EQ(o.start(), HalStatus::ok);
  ParticleFrame f;
  ASSERT_EQ(o.read(f), HalStatus::ok);
  EXPECT_EQ(f.observed_count, 3);
  EXPECT_EQ(f.particle_count, 3);
  EXPECT_EQ(f.header.status_bits, 0u);
  ASSERT_EQ(o.read(f), HalStatus::ok);
  EXPECT_TRUE(std::isnan(f.positions[3]));  // particle 1, the highest, hidden
  EXPECT_TRUE(std::isnan(f.positions[5]));  // particle 2 was not observed in the recording
  EXPECT_DOUBLE_EQ(f.positions[1], 0.1);
  EXPECT_EQ(f.observed_count, 1);
  EXPECT_EQ(f.header.status_bits, kFramePartial);
  EXPECT_EQ(o.fault_counters().of(FaultKind::occlude), 1u);
}

TEST(HalReplay, MalformedChannelsAreRefused) {
  ManualClock clock(0.0);
  RecordedChannel empty;
  empty.width = 6;
  ReplayForceTorque a(empty, clock);
  EXPECT_EQ(a.configure(), HalStatus::invalid_argument);
  EXPECT_EQ(a.state(), LifecycleState::unconfigured);

  RecordedChannel backwards = wrench_channel();
  backwards.t_s[4] = backwards.t_s[3];
  ReplayForceTorque b(backwards, clock);
  EXPECT_EQ(b.configure(), HalStatus::invalid_argument);

  RecordedChannel short_values = wrench_channel();
  short_values.values.pop_back();
  ReplayForceTorque d(short_values, clock);
  EXPECT_EQ(d.configure(), HalStatus::invalid_argument);

  RecordedChannel nan_time = wrench_channel();
  nan_time.t_s[0] = kNaN;
  ReplayForceTorque e(nan_time, clock);
  EXPECT_EQ(e.configure(), HalStatus::invalid_argument);

  const RecordedChannel good = wrench_channel();
  ReplayGripper wrong_width(good, clock);
  EXPECT_EQ(wrong_width.configure(), HalStatus::invalid_argument);
  ReplayParticleObserver odd(good, 4, clock);
  EXPECT_EQ(odd.configure(), HalStatus::invalid_argument);
  ReplayForceTorque slow(good, clock, ReplayTiming{ReplayMode::realtime, 0.0});
  EXPECT_EQ(slow.configure(), HalStatus::invalid_argument);

  const RecordedChannel one_width{{0.0}, {0.05, 1.0}, 2};
  ReplayGripper gripper_bus_off(one_width, clock);
  EXPECT_EQ(gripper_bus_off.add_fault({0.0, 1.0, FaultKind::bus_off, kNaN}),
            HalStatus::ok);  // unchecked until configure
  EXPECT_EQ(gripper_bus_off.configure(), HalStatus::unsupported);
}

}  // namespace
}  // namespace pliant::hal
