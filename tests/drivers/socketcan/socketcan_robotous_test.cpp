// RobotousRftForceTorque against the RFT emulator over a socketpair, on a manual clock:
// streaming start and stop, the hand-computed scaling, device bias, output rate, overload bits,
// broken packet pairs, malformed frames, timeouts with a repeated stream request, bus-off,
// disconnect and reconnect.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "socketcan_fixture.hpp"

namespace pliant::drivers::socketcan {
namespace {

using hal::HalStatus;
using hal::WrenchReading;
using test::kTick;
using test::RftRig;

// The hand packet of socketcan_protocol_test.cpp: raw counts and the wrench at dividers 50, 2000.
constexpr std::int16_t kRaw[6] = {100, -50, 2500, -2000, 1000, 1};
constexpr double kWrench[6] = {2.0, -1.0, 50.0, -1.0, 0.5, 0.0005};

void expect_wrench(const WrenchReading& w, const double expected[6]) {
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(w.wrench[k], expected[k], 1e-12) << "axis " << k;
}

TEST(SocketCanRft, StartsTheStreamAndDecodesPackets) {
  RftRig rig;
  ASSERT_TRUE(rig.pair());
  rig.emulator->set_raw(kRaw);
  ASSERT_EQ(rig.make(), HalStatus::ok);
  WrenchReading w;
  EXPECT_FALSE(rig.emulator->streaming());
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);  // sends "start streaming"
  EXPECT_TRUE(rig.emulator->streaming());
  EXPECT_TRUE(rig.ft->streaming_requested());
  for (int i = 1; i <= 10; ++i) {
    ASSERT_EQ(rig.cycle(w), HalStatus::ok);
    EXPECT_EQ(w.header.sequence, static_cast<std::uint64_t>(i));
  }
  expect_wrench(w, kWrench);
  EXPECT_EQ(w.header.status_bits, 0u);
  EXPECT_DOUBLE_EQ(w.header.stamp_s, rig.clock.now_s());
  EXPECT_EQ(rig.ft->protocol_counters().stream_requests, 1u);
  EXPECT_EQ(rig.ft->protocol_counters().complete_packets, 10u);
  EXPECT_EQ(rig.ft->protocol_counters().dropped_frames(), 0u);
  EXPECT_EQ(rig.ft->last_packet().raw[3], -2000);
  EXPECT_EQ(rig.emulator->counters().bias_commands, 0u);
  EXPECT_EQ(rig.emulator->counters().rate_commands, 0u);
}

TEST(SocketCanRft, EmulatorLoadInSiUnitsRoundsAndSaturates) {
  RftRig rig;
  ASSERT_TRUE(rig.pair());
  const double load[6] = {2.0, -1.0, 50.0, -1.0, 0.5, 0.0005};  // = kRaw at dividers 50, 2000
  rig.emulator->set_wrench(load);
  ASSERT_EQ(rig.make(), HalStatus::ok);
  WrenchReading w;
  ASSERT_EQ(rig.next_sample(w), HalStatus::ok);
  expect_wrench(w, kWrench);
  const double beyond[6] = {1e6, -1e6, std::numeric_limits<double>::quiet_NaN(), 0, 0, 0};
  rig.emulator->set_wrench(beyond);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_DOUBLE_EQ(w.wrench[0], 32767.0 / 50.0);
  EXPECT_DOUBLE_EQ(w.wrench[1], -32768.0 / 50.0);
  EXPECT_DOUBLE_EQ(w.wrench[2], 0.0);
}

TEST(SocketCanRft, TheNewestPacketWinsAndTheRestShowAsDrops) {
  RftRig rig;
  ASSERT_TRUE(rig.pair());
  rig.emulator->set_raw(kRaw);
  ASSERT_EQ(rig.make(), HalStatus::ok);
  WrenchReading w;
  (void)rig.cycle(w);
  ASSERT_EQ(rig.cycle(w, 3), HalStatus::ok);  // reads 1 packet; 3 more are sent
  const std::int16_t later[6] = {50, 0, 0, 0, 0, 0};
  rig.emulator->set_raw(later);
  rig.emulator->stream(1);
  ASSERT_EQ(rig.cycle(w, 0), HalStatus::ok);
  EXPECT_EQ(w.header.sequence, 5u);
  EXPECT_DOUBLE_EQ(w.wrench[0], 1.0);
  EXPECT_EQ(rig.ft->counters().dropped, 3u);
}

TEST(SocketCanRft, DeviceBiasOnStartAndOnRequest) {
  RftRig rig;
  rig.config.bias_on_start = true;
  rig.config.output_rate_code = 8;  // 1000 Hz
  ASSERT_TRUE(rig.pair());
  rig.emulator->set_raw(kRaw);
  ASSERT_EQ(rig.make(), HalStatus::ok);
  WrenchReading w;
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);
  EXPECT_TRUE(rig.emulator->bias_active());
  EXPECT_EQ(rig.emulator->output_rate_code(), 8);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  const double zero[6] = {0, 0, 0, 0, 0, 0};
  expect_wrench(w, zero);
  // The answer to "set output rate" is a complete non-F/T packet: consumed and counted.
  EXPECT_EQ(rig.ft->protocol_counters().other_responses, 1u);
  // A load of +50 counts on Fz over the bias reads 1 N.
  std::int16_t loaded[6] = {100, -50, 2550, -2000, 1000, 1};
  rig.emulator->set_raw(loaded);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);  // the packet sent before the change
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_DOUBLE_EQ(w.wrench[2], 1.0);
  // tare() zeroes on the current load; clear_tare() goes back to absolute readings.
  ASSERT_EQ(rig.ft->tare(), HalStatus::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  expect_wrench(w, zero);
  ASSERT_EQ(rig.ft->clear_tare(), HalStatus::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_DOUBLE_EQ(w.wrench[2], 51.0);
  EXPECT_EQ(rig.emulator->counters().bias_commands, 3u);
  EXPECT_FALSE(rig.emulator->bias_active());
}

TEST(SocketCanRft, OverloadSetsFaultBits) {
  RftRig rig;
  ASSERT_TRUE(rig.pair());
  rig.emulator->set_raw(kRaw);
  ASSERT_EQ(rig.make(), HalStatus::ok);
  WrenchReading w;
  (void)rig.cycle(w);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  rig.emulator->set_overload(0x05);  // Fx and Fz over range
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(w.header.status_bits, 0u);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(w.header.status_bits, hal::kFtAdcHigh | hal::kFtAnyError);
  EXPECT_NE(w.header.status_bits & hal::kFtFaultMask, 0u);
  EXPECT_EQ(rig.ft->last_overload(), 0x05);
  EXPECT_EQ(rig.ft->counters().fault_samples, 1u);
  EXPECT_EQ(rig.ft->protocol_counters().overload_packets, 1u);
}

TEST(SocketCanRft, BrokenPairsAreCountedAndNeverMixed) {
  RftRig rig;
  ASSERT_TRUE(rig.pair());
  rig.emulator->set_raw(kRaw);
  ASSERT_EQ(rig.make(), HalStatus::ok);
  WrenchReading w;
  (void)rig.cycle(w);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  const RftCounters& c = rig.ft->protocol_counters();
  // Lost second half: the next first half replaces the orphan first half.
  rig.emulator->faults().drop_second_halves = 1;
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);  // the packet sent before the fault
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  expect_wrench(w, kWrench);
  EXPECT_EQ(c.incomplete_packets, 1u);
  // Lost first half: the second half is an orphan.
  rig.emulator->faults().drop_first_halves = 1;
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(c.incomplete_packets, 2u);
  // Swapped halves: an orphan second, then a first half replaced by the next packet's.
  rig.emulator->faults().swap_halves = 1;
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  expect_wrench(w, kWrench);
  EXPECT_EQ(c.incomplete_packets, 4u);
  // Second half with 7 bytes: dropped as wrong DLC, its first half replaced.
  rig.emulator->faults().wrong_dlc = 1;
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(c.wrong_dlc, 1u);
  EXPECT_EQ(c.incomplete_packets, 5u);
  expect_wrench(w, kWrench);
}

TEST(SocketCanRft, ForeignAndMalformedFramesAreCountedDrops) {
  RftRig rig;
  ASSERT_TRUE(rig.pair());
  rig.emulator->set_raw(kRaw);
  ASSERT_EQ(rig.make(), HalStatus::ok);
  WrenchReading w;
  (void)rig.cycle(w);
  const std::uint8_t eight[8] = {11, 0, 0, 0, 0, 0, 0, 0};
  CanFrame ext = make_standard_frame(0x01, eight, 8);
  ext.id |= kCanEffFlag;
  ASSERT_EQ(rig.emulator->send_raw(make_standard_frame(0x123, eight, 8)), CanIo::ok);
  ASSERT_EQ(rig.emulator->send_raw(ext), CanIo::ok);
  ASSERT_EQ(rig.emulator->send_raw(make_standard_frame(0x02, eight, 3)), CanIo::ok);
  const unsigned char junk[20] = {};
  ASSERT_EQ(rig.sensor_end.send_record(junk, sizeof junk), CanIo::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  expect_wrench(w, kWrench);
  EXPECT_EQ(rig.ft->protocol_counters().foreign_frames, 2u);
  EXPECT_EQ(rig.ft->protocol_counters().wrong_dlc, 1u);
  EXPECT_EQ(rig.ft->link_counters().malformed_records, 1u);
  EXPECT_EQ(rig.ft->protocol_counters().dropped_frames(), 3u);
}

TEST(SocketCanRft, QuietStreamTimesOutAndIsRequestedAgain) {
  RftRig rig;
  rig.config.timeout_s = 10 * kTick;
  ASSERT_TRUE(rig.pair());
  rig.emulator->set_raw(kRaw);
  ASSERT_EQ(rig.make(), HalStatus::ok);
  WrenchReading w;
  (void)rig.cycle(w);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  // The sensor stops streaming (as after a reboot): a stop command reaches it from elsewhere.
  ASSERT_EQ(rig.device_end.send(rft::make_command(rig.config.ids, rft::kCmdFtStop)), CanIo::ok);
  ASSERT_EQ(rig.cycle(w, 0), HalStatus::ok);  // the last packet
  int empty = 0;
  HalStatus s = HalStatus::no_data;
  while ((s = rig.cycle(w, 0)) == HalStatus::no_data && empty < 50) ++empty;
  EXPECT_EQ(s, HalStatus::timeout);
  EXPECT_EQ(empty, 10);
  // That read asked for the stream again; the emulator streams from the next cycle.
  EXPECT_TRUE(rig.emulator->streaming());
  EXPECT_EQ(rig.ft->protocol_counters().stream_requests, 2u);
  ASSERT_EQ(rig.cycle(w), HalStatus::timeout);  // the emulator sends its first packet after this read
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(rig.ft->counters().timeouts, 2u);
  // A sensor that never answers is asked once per timeout, not once per read.
  rig.emulator->faults().mute = true;
  for (int i = 0; i < 45; ++i) (void)rig.cycle(w);
  EXPECT_EQ(rig.ft->protocol_counters().stream_requests, 6u);
}

TEST(SocketCanRft, BusOffErrorFramesAndRestart) {
  RftRig rig;
  ASSERT_TRUE(rig.pair());
  rig.emulator->set_raw(kRaw);
  ASSERT_EQ(rig.make(), HalStatus::ok);
  WrenchReading w;
  (void)rig.cycle(w);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  const std::uint8_t overflow[8] = {0, kCanCtrlRxOverflow, 0, 0, 0, 0, 0, 0};
  ASSERT_EQ(rig.emulator->send_error(kCanErrController, overflow), CanIo::ok);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(w.header.status_bits, hal::kFtCanBusError);
  EXPECT_EQ(rig.ft->link_counters().rx_overflows, 1u);
  ASSERT_EQ(rig.emulator->send_error(kCanErrBusOff | kCanErrNoAck), CanIo::ok);
  EXPECT_EQ(rig.cycle(w, 0), HalStatus::bus_off);
  EXPECT_EQ(rig.cycle(w, 0), HalStatus::bus_off);
  EXPECT_EQ(rig.ft->link_counters().no_ack, 1u);
  const std::uint8_t active[8] = {0, kCanCtrlActive, 0, 0, 0, 0, 0, 0};
  ASSERT_EQ(rig.emulator->send_error(kCanErrController, active), CanIo::ok);
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(rig.ft->link_counters().bus_restarts, 1u);
  EXPECT_EQ(rig.ft->counters().bus_off, 2u);
}

TEST(SocketCanRft, ReconnectRequestsTheStreamButNeverRebiases) {
  RftRig rig;
  rig.config.bias_on_start = true;
  rig.config.link.reconnect_interval_s = 5 * kTick;
  rig.config.link.samples_after_restart = 1;
  const std::string address = test::unique_address("rft");
  SeqpacketCanListener listener;
  ASSERT_EQ(listener.listen(address.c_str()), HalStatus::ok);
  ASSERT_EQ(rig.device_end.set_address(address.c_str()), HalStatus::ok);
  rig.emulator = std::make_unique<RobotousRftEmulator>(rig.sensor_end, rig.emulator_config);
  rig.emulator->set_raw(kRaw);
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_EQ(listener.accept(rig.sensor_end), HalStatus::ok);
  WrenchReading w;
  (void)rig.cycle(w);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  rig.emulator->disconnect();
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);  // the packet already queued
  EXPECT_EQ(rig.cycle(w), HalStatus::disconnected);
  // The emulator "reboots": not streaming, no bias.
  RobotousRftEmulator rebooted(rig.sensor_end, rig.emulator_config);
  rebooted.set_raw(kRaw);
  rig.emulator.reset();
  int waiting = 0;
  HalStatus s = HalStatus::disconnected;
  while (waiting < 20) {
    (void)rig.clock.advance(kTick);
    s = rig.ft->read(w);
    if (s != HalStatus::disconnected) break;
    ++waiting;
  }
  EXPECT_EQ(waiting, 3);
  ASSERT_EQ(s, HalStatus::no_data);  // reconnected, stream requested
  ASSERT_EQ(listener.accept(rig.sensor_end), HalStatus::ok);
  rebooted.service();
  EXPECT_TRUE(rebooted.streaming());
  EXPECT_FALSE(rebooted.bias_active());  // no bias after a reconnect
  EXPECT_EQ(rebooted.counters().bias_commands, 0u);
  rebooted.stream(1);
  (void)rig.clock.advance(kTick);
  EXPECT_EQ(rig.ft->read(w), HalStatus::no_data);  // held: the first sample after the reconnect
  rebooted.stream(1);
  (void)rig.clock.advance(kTick);
  ASSERT_EQ(rig.ft->read(w), HalStatus::ok);
  expect_wrench(w, kWrench);  // absolute: the bias was lost with the reboot, and not redone
  EXPECT_EQ(rig.ft->counters().reconnects, 1u);
  EXPECT_EQ(rig.ft->link_counters().held_samples, 1u);
}

TEST(SocketCanRft, StopSendsTheStopCommand) {
  RftRig rig;
  ASSERT_TRUE(rig.pair());
  ASSERT_EQ(rig.make(), HalStatus::ok);
  WrenchReading w;
  (void)rig.cycle(w);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  ASSERT_EQ(rig.ft->stop(), HalStatus::ok);
  rig.emulator->service();
  EXPECT_FALSE(rig.emulator->streaming());
  EXPECT_EQ(rig.emulator->counters().stream_stops, 1u);
  EXPECT_EQ(rig.ft->tare(), HalStatus::wrong_state);
  EXPECT_EQ(rig.ft->read(w), HalStatus::wrong_state);
  // Start again: the stream is requested again, packets queued meanwhile were flushed.
  rig.emulator->stream(1);  // not streaming: nothing
  ASSERT_EQ(rig.ft->start(), HalStatus::ok);
  EXPECT_EQ(rig.cycle(w), HalStatus::no_data);
  ASSERT_EQ(rig.cycle(w), HalStatus::ok);
  EXPECT_EQ(w.header.sequence, 2u);
  EXPECT_EQ(rig.ft->protocol_counters().stream_requests, 2u);
}

TEST(SocketCanRft, BadConfigurationsAreRefused) {
  auto refused = [](void (*edit)(RobotousRftConfig&)) {
    RftRig rig;
    edit(rig.config);
    if (!rig.pair()) return false;
    RobotousRftForceTorque ft(rig.device_end, rig.clock, rig.config);
    return ft.configure() == HalStatus::invalid_argument && ft.state() == hal::LifecycleState::unconfigured;
  };
  EXPECT_TRUE(refused([](RobotousRftConfig& c) { c.ids.response_2 = c.ids.response_1; }));
  EXPECT_TRUE(refused([](RobotousRftConfig& c) { c.ids.command = 0x800; }));
  EXPECT_TRUE(refused([](RobotousRftConfig& c) { c.force_divider = 0; }));
  EXPECT_TRUE(refused([](RobotousRftConfig& c) { c.torque_divider = std::numeric_limits<double>::quiet_NaN(); }));
  EXPECT_TRUE(refused([](RobotousRftConfig& c) { c.output_rate_code = 9; }));
  EXPECT_TRUE(refused([](RobotousRftConfig& c) { c.timeout_s = -1; }));
  EXPECT_TRUE(refused([](RobotousRftConfig& c) { c.link.reconnect_interval_s = 0; }));
}

}  // namespace
}  // namespace pliant::drivers::socketcan
