// No-heap proof for the modbus driver's per-cycle paths: the codecs, the stream parser, and the
// devices' read/write once configured (gripper over Modbus TCP to the emulator, FT 300 polling,
// FT 300 stream over a pseudo-terminal). The counter is global, so the emulator's server thread
// is covered too while it answers.
#include "support/counting_allocator.hpp"

#include <gtest/gtest.h>

#include <fcntl.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cstdint>
#include <string>
#include <vector>

#include "pliant/drivers/modbus/emulator/modbus_emulator.hpp"
#include "pliant/drivers/modbus/ft300_codec.hpp"
#include "pliant/drivers/modbus/modbus_crc.hpp"
#include "pliant/drivers/modbus/robotiq_2f_codec.hpp"
#include "pliant/drivers/modbus/robotiq_ft300.hpp"
#include "pliant/drivers/modbus/robotiq_gripper.hpp"

namespace pliant::drivers::modbus {
namespace {

using hal::HalStatus;
using pliant::test::AllocationCounter;
using pliant::test::AllocationCounts;
namespace r2f = robotiq2f;

TEST(ModbusAllocation, CodecsAndParserAllocateNothing) {
  std::vector<std::uint8_t> stream;
  for (std::int16_t i = 0; i < 20; ++i) {
    const std::int16_t counts[6] = {i, static_cast<std::int16_t>(-i), 3, 4, 5, 6};
    std::uint8_t f[ft300::kFrameSize];
    ft300::encode_stream_frame(counts, f);
    if (i % 5 == 3) f[7] ^= 0x01;
    stream.insert(stream.end(), f, f + ft300::kFrameSize);
    stream.push_back(0x20);
    stream.push_back(0x11);
  }
  ft300::StreamParser parser;
  r2f::Scaling scaling;
  std::uint64_t sink = 0;

  AllocationCounter counter;
  for (unsigned v = 0; v < 256; ++v) {
    const std::uint16_t regs[3] = {static_cast<std::uint16_t>(v << 8), static_cast<std::uint16_t>(v), 0x1234};
    const r2f::Status s = r2f::decode_status(regs);
    hal::GripperReading r;
    r2f::to_reading(s, scaling, r);
    std::uint16_t out[3];
    r2f::encode_status(s, out);
    r2f::Command c;
    c.position = r2f::width_to_position(0.0003 * v, scaling);
    c.speed = r2f::speed_to_byte(0.001 * v, scaling);
    c.force = r2f::force_to_byte(1.0 * v, scaling);
    r2f::encode_command(c, out);
    sink += r.header.status_bits + out[1];
  }
  const std::uint16_t wrench_regs[6] = {1, 2, 3, 4, 5, 6};
  double w[6];
  ft300::registers_to_wrench(wrench_regs, w);
  for (std::size_t at = 0; at < stream.size(); at += 7) {
    sink += parser.feed(stream.data() + at, std::min<std::size_t>(7, stream.size() - at));
  }
  sink += modbus_crc16(stream.data(), stream.size());
  const AllocationCounts counts = counter.stop();
  EXPECT_EQ(counts.total(), 0u);
  EXPECT_EQ(parser.counters().frames, 16u);
  EXPECT_EQ(parser.counters().crc_errors, 4u);
  EXPECT_NE(sink, 0u);
}

TEST(ModbusAllocation, DeviceReadsAndWritesAllocateNothing) {
  ModbusEmulatorConfig ec;
  ec.gripper.activation_time_s = 0.1;
  ModbusEmulator emulator(ec);
  std::string error;
  ASSERT_TRUE(emulator.start(&error)) << error;
  hal::ManualClock clock;
  RobotiqGripperConfig gc;
  gc.link.transport = ModbusTransport::tcp;
  gc.link.port = emulator.port();
  gc.link.response_timeout_s = 2.0;
  gc.reset_hold_s = 0;
  RobotiqGripper gripper(clock, gc);
  ASSERT_EQ(gripper.configure(), HalStatus::ok);
  ASSERT_EQ(gripper.start(), HalStatus::ok);
  hal::GripperReading g;
  ASSERT_EQ(gripper.read(g), HalStatus::ok);
  emulator.advance(0.1);
  ASSERT_EQ(gripper.read(g), HalStatus::ok);
  ASSERT_TRUE(gripper.activated());
  RobotiqFt300Config fc;
  fc.link = gc.link;
  RobotiqFt300 ft(clock, fc);
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  hal::WrenchReading w;
  ASSERT_EQ(ft.read(w), HalStatus::ok);  // first calls out of the way

  HalStatus worst = HalStatus::ok;
  AllocationCounter counter;
  for (int i = 0; i < 20; ++i) {
    const HalStatus a = gripper.move_to(0.001 * i, 0.1, 50);
    const HalStatus b = gripper.read(g);
    const HalStatus c = ft.read(w);
    if (a != HalStatus::ok) worst = a;
    if (b != HalStatus::ok) worst = b;
    if (c != HalStatus::ok) worst = c;
  }
  const HalStatus d = gripper.freeze();
  const AllocationCounts counts = counter.stop();
  EXPECT_EQ(counts.total(), 0u);
  EXPECT_EQ(worst, HalStatus::ok);
  EXPECT_EQ(d, HalStatus::ok);
}

TEST(ModbusAllocation, StreamReadsAllocateNothing) {
  const int master = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  ASSERT_GE(master, 0);
  ASSERT_EQ(grantpt(master), 0);
  ASSERT_EQ(unlockpt(master), 0);
  char name[128];
  ASSERT_EQ(ptsname_r(master, name, sizeof name), 0);
  hal::ManualClock clock;
  RobotiqFt300Config fc;
  fc.mode = Ft300Mode::stream;
  fc.link.device = name;
  RobotiqFt300 ft(clock, fc);
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  const int watch = ::open(name, O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  ASSERT_GE(watch, 0);
  std::uint8_t frames[5 * ft300::kFrameSize];
  for (int i = 0; i < 5; ++i) {
    const std::int16_t counts[6] = {static_cast<std::int16_t>(i), 0, 0, 0, 0, 0};
    ft300::encode_stream_frame(counts, frames + i * static_cast<int>(ft300::kFrameSize));
  }
  ASSERT_EQ(::write(master, frames, sizeof frames), static_cast<ssize_t>(sizeof frames));
  int queued = 0;
  for (int i = 0; i < 2000 && queued < static_cast<int>(sizeof frames); ++i) {
    ASSERT_EQ(ioctl(watch, FIONREAD, &queued), 0);
    if (queued < static_cast<int>(sizeof frames)) usleep(1000);
  }
  hal::WrenchReading w;
  AllocationCounter counter;
  const HalStatus first = ft.read(w);
  const HalStatus second = ft.read(w);
  const AllocationCounts counts = counter.stop();
  EXPECT_EQ(counts.total(), 0u);
  EXPECT_EQ(first, HalStatus::ok);
  EXPECT_EQ(second, HalStatus::no_data);
  EXPECT_EQ(ft.stream_counters().frames, 5u);
  ::close(watch);
  ASSERT_EQ(ft.stop(), HalStatus::ok);
  ASSERT_EQ(ft.cleanup(), HalStatus::ok);
  ::close(master);
}

}  // namespace
}  // namespace pliant::drivers::modbus
