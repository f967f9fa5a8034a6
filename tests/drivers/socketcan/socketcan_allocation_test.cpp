// No-heap proof for the socketcan sensors' read(): setup, polling and streaming, malformed
// frames, error frames, bus-off and restart, timeouts, a disconnect and the reconnect through
// the named listener, all with the tests' counting allocator armed around every read (and
// around the emulators, which are allocation-free as well).
#include "support/counting_allocator.hpp"

#include <gtest/gtest.h>

#include <string>

#include "socketcan_fixture.hpp"

namespace pliant::drivers::socketcan {
namespace {

using hal::HalStatus;
using pliant::test::AllocationCounter;
using pliant::test::AllocationCounts;
using test::kTick;

TEST(SocketCanAllocation, AtiReadsAllocateNothing) {
  test::AtiRig rig;
  rig.config.response_timeout_s = 4 * kTick;
  rig.config.timeout_s = 30 * kTick;
  rig.config.link.reconnect_interval_s = 8 * kTick;
  rig.config.link.samples_after_restart = 1;
  const std::string address = test::unique_address("alloc-ati");
  SeqpacketCanListener listener;
  ASSERT_EQ(listener.listen(address.c_str()), HalStatus::ok);
  ASSERT_EQ(rig.device_end.set_address(address.c_str()), HalStatus::ok);
  rig.emulator = std::make_unique<AtiNetCanEmulator>(rig.sensor_end, rig.emulator_config);
  rig.emulator->set_gauges(test::kHandGauges);
  ASSERT_EQ(rig.make(), HalStatus::ok);
  ASSERT_EQ(listener.accept(rig.sensor_end), HalStatus::ok);
  hal::WrenchReading w;
  int ok = 0, bus_off = 0, disconnected = 0;
  const std::uint8_t junk[8] = {1, 2, 3, 4, 5, 6, 7, 8};
  AllocationCounts counts;
  {
    AllocationCounter counter;
    for (int k = 0; k < 400; ++k) {
      if (k == 50) (void)rig.ft->tare(5);
      if (k == 80) rig.emulator->faults().drop_second_halves = 2;
      if (k == 100) (void)rig.emulator->send_raw(make_standard_frame(0x20a, junk, 8));
      if (k == 101) (void)rig.emulator->send_raw(make_standard_frame(0x300, junk, 8));
      if (k == 102) (void)rig.sensor_end.send_record(junk, 5);
      if (k == 120) (void)rig.emulator->send_error(kCanErrController, junk);
      if (k == 150) (void)rig.emulator->send_error(kCanErrBusOff);
      if (k == 160) (void)rig.emulator->send_error(kCanErrRestarted);
      if (k == 200) rig.emulator->faults().mute = true;
      if (k == 260) rig.emulator->faults().mute = false;
      if (k == 300) rig.emulator->disconnect();
      if (k > 300 && !rig.sensor_end.is_open()) (void)listener.accept(rig.sensor_end);
      const HalStatus s = rig.cycle(w);
      ok += s == HalStatus::ok ? 1 : 0;
      bus_off += s == HalStatus::bus_off ? 1 : 0;
      disconnected += s == HalStatus::disconnected ? 1 : 0;
    }
    counts = counter.stop();
  }
  EXPECT_EQ(counts.total(), 0u) << "news=" << counts.news << " mallocs=" << counts.mallocs;
  EXPECT_GT(ok, 200);
  EXPECT_EQ(bus_off, 10);
  EXPECT_GT(disconnected, 0);
  EXPECT_EQ(rig.ft->counters().reconnects, 1u);
  EXPECT_GT(rig.ft->counters().timeouts, 0u);
  EXPECT_EQ(rig.ft->protocol_counters().tares_completed, 1u);
  EXPECT_TRUE(rig.ft->ready());
}

TEST(SocketCanAllocation, RobotousReadsAllocateNothing) {
  test::RftRig rig;
  rig.config.timeout_s = 10 * kTick;
  rig.config.output_rate_code = 7;
  rig.config.bias_on_start = true;
  ASSERT_TRUE(rig.pair());
  const std::int16_t raw[6] = {100, -50, 2500, -2000, 1000, 1};
  rig.emulator->set_raw(raw);
  ASSERT_EQ(rig.make(), HalStatus::ok);
  hal::WrenchReading w;
  int ok = 0, bus_off = 0, timeouts = 0;
  AllocationCounts counts;
  {
    AllocationCounter counter;
    for (int k = 0; k < 300; ++k) {
      if (k == 30) (void)rig.ft->tare();
      if (k == 40) rig.emulator->set_overload(3);
      if (k == 41) rig.emulator->set_overload(0);
      if (k == 60) rig.emulator->faults().drop_second_halves = 2;
      if (k == 70) rig.emulator->faults().swap_halves = 2;
      if (k == 90) (void)rig.emulator->send_error(kCanErrBusOff);
      if (k == 95) (void)rig.emulator->send_error(kCanErrRestarted);
      if (k == 150) rig.emulator->faults().mute = true;
      if (k == 200) rig.emulator->faults().mute = false;
      const HalStatus s = rig.cycle(w, k % 3);
      ok += s == HalStatus::ok ? 1 : 0;
      bus_off += s == HalStatus::bus_off ? 1 : 0;
      timeouts += s == HalStatus::timeout ? 1 : 0;
    }
    (void)rig.ft->stop();
    counts = counter.stop();
  }
  EXPECT_EQ(counts.total(), 0u) << "news=" << counts.news << " mallocs=" << counts.mallocs;
  EXPECT_GT(ok, 100);
  EXPECT_GT(bus_off, 0);
  EXPECT_GT(timeouts, 0);
  EXPECT_GT(rig.ft->protocol_counters().incomplete_packets, 0u);
}

}  // namespace
}  // namespace pliant::drivers::socketcan
