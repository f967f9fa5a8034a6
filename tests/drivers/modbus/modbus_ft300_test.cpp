// RobotiqFt300: polling over Modbus TCP against the emulator (scaling, the grip-force coupling,
// tare, timeout, disconnection), and the binary stream mode over a pseudo-terminal that the
// test writes frames into (start request, frames, split frames, CRC errors, garbage, dropped
// frames, silence, the jam signal on stop, a vanished port).
#include <gtest/gtest.h>

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "pliant/drivers/modbus/emulator/modbus_emulator.hpp"
#include "pliant/drivers/modbus/robotiq_ft300.hpp"
#include "pliant/drivers/modbus/robotiq_gripper.hpp"

namespace pliant::drivers::modbus {
namespace {

using hal::HalStatus;

constexpr double kPastReconnectS = 0.15;  // more than reconnect_interval_s (0.1), clear of rounding

void tick(hal::ManualClock& clock, double dt_s) { ASSERT_EQ(clock.advance(dt_s), HalStatus::ok); }

RobotiqFt300Config polling_config(std::uint16_t port) {
  RobotiqFt300Config c;
  c.link.transport = ModbusTransport::tcp;
  c.link.port = port;
  c.link.response_timeout_s = 2.0;
  c.link.reconnect_interval_s = 0.1;
  return c;
}

TEST(RobotiqFt300PollingTest, ScalesTheRegisters) {
  ModbusEmulator emulator;
  ASSERT_TRUE(emulator.start());
  hal::ManualClock clock(3.0);
  RobotiqFt300 ft(clock, polling_config(emulator.port()));
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  const double w[6] = {1.5, -2.25, 10.0, 0.125, -0.5, 3.2};
  emulator.set_wrench(w);
  EXPECT_EQ(emulator.holding_register(180), 0);  // registers follow at the next request
  hal::WrenchReading r;
  ASSERT_EQ(ft.read(r), HalStatus::ok);
  for (int i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(r.wrench[i], w[i]) << i;
  EXPECT_EQ(r.header.sequence, 1u);
  EXPECT_DOUBLE_EQ(r.header.stamp_s, 3.0);
  EXPECT_EQ(r.header.status_bits, 0u);
  EXPECT_EQ(emulator.holding_register(181), 0xff1f);  // -225
  // Resolution: 0.01 N and 0.001 N m.
  const double fine[6] = {0.004, 0.006, -0.006, 0.0004, 0.0006, -327.68e-1};
  emulator.set_wrench(fine);
  ASSERT_EQ(ft.read(r), HalStatus::ok);
  EXPECT_DOUBLE_EQ(r.wrench[0], 0.0);
  EXPECT_DOUBLE_EQ(r.wrench[1], 0.01);
  EXPECT_DOUBLE_EQ(r.wrench[2], -0.01);
  EXPECT_DOUBLE_EQ(r.wrench[3], 0.0);
  EXPECT_DOUBLE_EQ(r.wrench[4], 0.001);
  EXPECT_DOUBLE_EQ(r.wrench[5], -32.768);
  EXPECT_EQ(ft.counters().samples, 2u);
}

TEST(RobotiqFt300PollingTest, TareAndGripForceCoupling) {
  ModbusEmulatorConfig ec;
  ec.ft_grip_force_axis = 2;
  ec.gripper.activation_time_s = 0.1;
  ec.gripper.object_width_m = 0.05;
  ec.gripper.object_stiffness_n_per_m = 1000;
  ModbusEmulator emulator(ec);
  ASSERT_TRUE(emulator.start());
  hal::ManualClock clock;
  RobotiqFt300 ft(clock, polling_config(emulator.port()));
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  const double base[6] = {0.5, 0.0, -3.0, 0.0, 0.02, 0.0};
  emulator.set_wrench(base);
  ft.request_tare();
  hal::WrenchReading r;
  ASSERT_EQ(ft.read(r), HalStatus::ok);
  for (double v : r.wrench) EXPECT_DOUBLE_EQ(v, 0.0);
  EXPECT_DOUBLE_EQ(ft.bias()[2], -3.0);
  EXPECT_EQ(ft.driver_counters().tares, 1u);

  // A gripper on the same emulator squeezes the soft object; Fz carries the grip force.
  RobotiqGripperConfig gc;
  gc.link = polling_config(emulator.port()).link;
  gc.reset_hold_s = 0;
  RobotiqGripper gripper(clock, gc);
  ASSERT_EQ(gripper.configure(), HalStatus::ok);
  ASSERT_EQ(gripper.start(), HalStatus::ok);
  hal::GripperReading g;
  ASSERT_EQ(gripper.read(g), HalStatus::ok);
  emulator.advance(0.1);
  ASSERT_EQ(gripper.read(g), HalStatus::ok);
  ASSERT_TRUE(gripper.activated());
  ASSERT_EQ(gripper.move_to(0.0, 0.15, 20), HalStatus::ok);  // the weakest force, 20 N
  emulator.advance(2.0);
  ASSERT_EQ(ft.read(r), HalStatus::ok);
  EXPECT_NEAR(r.wrench[2], 20.0, 0.005);
  EXPECT_NEAR(r.wrench[0], 0.0, 1e-12);
}

TEST(RobotiqFt300PollingTest, TimeoutDisconnectAndReconnect) {
  ModbusEmulator emulator;
  ASSERT_TRUE(emulator.start());
  hal::ManualClock clock;
  RobotiqFt300 ft(clock, polling_config(emulator.port()));
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  hal::WrenchReading r;
  emulator.drop_replies(1);
  EXPECT_EQ(ft.read(r), HalStatus::timeout);
  EXPECT_EQ(ft.read(r), HalStatus::ok);
  emulator.corrupt_replies(1);
  EXPECT_EQ(ft.read(r), HalStatus::io_error);
  ASSERT_TRUE(emulator.disconnect_clients());
  EXPECT_EQ(ft.read(r), HalStatus::disconnected);
  tick(clock, kPastReconnectS);
  EXPECT_EQ(ft.read(r), HalStatus::ok);
  const hal::DeviceCounters& c = ft.counters();
  EXPECT_EQ(c.timeouts, 1u);
  EXPECT_EQ(c.io_errors, 1u);
  EXPECT_EQ(c.disconnected, 1u);
  EXPECT_EQ(c.reconnects, 1u);
  EXPECT_EQ(c.samples, 2u);
  EXPECT_EQ(ft.link_counters().reconnect_attempts, 1u);
}

TEST(RobotiqFt300PollingTest, MinPollPeriodAndBadConfiguration) {
  ModbusEmulator emulator;
  ASSERT_TRUE(emulator.start());
  hal::ManualClock clock;
  RobotiqFt300Config c = polling_config(emulator.port());
  c.min_poll_period_s = 0.01;
  RobotiqFt300 ft(clock, c);
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  hal::WrenchReading r;
  EXPECT_EQ(ft.read(r), HalStatus::ok);
  EXPECT_EQ(ft.read(r), HalStatus::no_data);
  EXPECT_EQ(ft.driver_counters().polls_skipped, 1u);
  tick(clock, 0.01);
  EXPECT_EQ(ft.read(r), HalStatus::ok);

  RobotiqFt300Config bad = c;
  bad.mode = Ft300Mode::stream;  // stream needs a serial device (rtu)
  RobotiqFt300 stream_over_tcp(clock, bad);
  EXPECT_EQ(stream_over_tcp.configure(), HalStatus::invalid_argument);
  bad = c;
  bad.min_poll_period_s = -1;
  RobotiqFt300 negative(clock, bad);
  EXPECT_EQ(negative.configure(), HalStatus::invalid_argument);
  RobotiqFt300Config odd_baud;
  odd_baud.mode = Ft300Mode::stream;
  odd_baud.link.baud = 12345;
  RobotiqFt300 odd(clock, odd_baud);
  EXPECT_EQ(odd.configure(), HalStatus::invalid_argument);
  EXPECT_EQ(RobotiqFt300Config{}.link.baud, 19200);
}

// The test's side of a pseudo-terminal: the driver opens the slave path as its serial port.
// A pty passes the master's bytes to the slave through the kernel's tty buffer asynchronously;
// write() waits (event-driven, at most 2 s) until the slave's input queue holds them, watched
// through a second slave descriptor, so the driver's next non-blocking read finds them all.
class Pty {
 public:
  Pty() {
    master_ = posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (master_ < 0 || grantpt(master_) != 0 || unlockpt(master_) != 0) return;
    char name[128];
    if (ptsname_r(master_, name, sizeof name) == 0) path_ = name;
  }
  ~Pty() { close(); }
  Pty(const Pty&) = delete;
  Pty& operator=(const Pty&) = delete;

  bool ok() const { return master_ >= 0 && !path_.empty(); }
  const std::string& path() const { return path_; }
  void close() {
    for (int* fd : {&watch_, &master_}) {
      if (*fd >= 0) ::close(*fd);
      *fd = -1;
    }
  }
  void write(const std::vector<std::uint8_t>& bytes) {
    if (watch_ < 0) watch_ = ::open(path_.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    ASSERT_GE(watch_, 0);
    const int before = queued();
    ASSERT_EQ(::write(master_, bytes.data(), bytes.size()), static_cast<ssize_t>(bytes.size()));
    for (int i = 0; i < 2000 && queued() < before + static_cast<int>(bytes.size()); ++i) usleep(1000);
    ASSERT_GE(queued(), before + static_cast<int>(bytes.size()));
  }
  // Reads exactly n bytes the driver wrote (waits at most 2 s for each chunk).
  std::vector<std::uint8_t> read(std::size_t n) {
    std::vector<std::uint8_t> out;
    while (out.size() < n) {
      pollfd p{master_, POLLIN, 0};
      if (poll(&p, 1, 2000) != 1) break;
      std::uint8_t buf[256];
      const ssize_t got = ::read(master_, buf, std::min(sizeof buf, n - out.size()));
      if (got <= 0) break;
      out.insert(out.end(), buf, buf + got);
    }
    return out;
  }

 private:
  int queued() const {
    int n = 0;
    return ioctl(watch_, FIONREAD, &n) == 0 ? n : -1;
  }

  int master_ = -1;
  int watch_ = -1;
  std::string path_;
};

std::vector<std::uint8_t> frame(std::int16_t fx, std::int16_t fy = 0, std::int16_t fz = 0, std::int16_t mx = 0,
                                std::int16_t my = 0, std::int16_t mz = 0) {
  const std::int16_t counts[6] = {fx, fy, fz, mx, my, mz};
  std::vector<std::uint8_t> f(ft300::kFrameSize);
  ft300::encode_stream_frame(counts, f.data());
  return f;
}

class RobotiqFt300StreamTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(pty.ok());
    config.mode = Ft300Mode::stream;
    config.link.device = pty.path();
    config.link.reconnect_interval_s = 0.1;
    ft = std::make_unique<RobotiqFt300>(clock, config);
    ASSERT_EQ(ft->configure(), HalStatus::ok);
    ASSERT_EQ(ft->start(), HalStatus::ok);
    std::uint8_t expected[ft300::kStartRequestSize];
    ft300::encode_stream_start_request(9, expected);
    const std::vector<std::uint8_t> request = pty.read(ft300::kStartRequestSize);
    ASSERT_EQ(request, std::vector<std::uint8_t>(expected, expected + ft300::kStartRequestSize));
  }

  Pty pty;
  hal::ManualClock clock;
  RobotiqFt300Config config;
  std::unique_ptr<RobotiqFt300> ft;
};

TEST_F(RobotiqFt300StreamTest, DeliversTheNewestFrame) {
  hal::WrenchReading r;
  EXPECT_EQ(ft->read(r), HalStatus::no_data);
  pty.write(frame(150, -250, 1000, 500, -1500, 32767));
  ASSERT_EQ(ft->read(r), HalStatus::ok);
  const double expected[6] = {1.5, -2.5, 10.0, 0.5, -1.5, 32.767};
  for (int i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(r.wrench[i], expected[i]) << i;
  EXPECT_EQ(r.header.sequence, 1u);
  EXPECT_EQ(r.header.status_bits, 0u);
  EXPECT_EQ(ft->read(r), HalStatus::no_data);
  // Three frames between two reads: the newest is delivered, two count as dropped.
  std::vector<std::uint8_t> three = frame(1);
  for (const std::int16_t v : {std::int16_t{2}, std::int16_t{3}}) {
    const auto f = frame(v);
    three.insert(three.end(), f.begin(), f.end());
  }
  pty.write(three);
  ASSERT_EQ(ft->read(r), HalStatus::ok);
  EXPECT_DOUBLE_EQ(r.wrench[0], 0.03);
  EXPECT_EQ(r.header.sequence, 4u);
  EXPECT_EQ(ft->counters().dropped, 2u);
  EXPECT_EQ(ft->stream_counters().frames, 4u);
}

TEST_F(RobotiqFt300StreamTest, SplitFramesGarbageAndCrcErrors) {
  hal::WrenchReading r;
  const auto f = frame(-700);
  pty.write(std::vector<std::uint8_t>(f.begin(), f.begin() + 10));
  EXPECT_EQ(ft->read(r), HalStatus::no_data);
  pty.write(std::vector<std::uint8_t>(f.begin() + 10, f.end()));
  ASSERT_EQ(ft->read(r), HalStatus::ok);
  EXPECT_DOUBLE_EQ(r.wrench[0], -7.0);
  // The sensor's answer to the start request, then a damaged frame, then a good one.
  std::vector<std::uint8_t> s = {0x09, 0x10, 0x01, 0x9a, 0x00, 0x01, 0x20, 0x4e};
  auto bad = frame(5);
  bad[4] ^= 0x10;
  s.insert(s.end(), bad.begin(), bad.end());
  const auto good = frame(6);
  s.insert(s.end(), good.begin(), good.end());
  pty.write(s);
  ASSERT_EQ(ft->read(r), HalStatus::ok);
  EXPECT_DOUBLE_EQ(r.wrench[0], 0.06);
  EXPECT_EQ(r.header.status_bits, hal::kFtCanBusError);  // transport degraded, not a fault
  EXPECT_EQ(r.header.status_bits & hal::kFtFaultMask, 0u);
  // The answer's last two bytes look like a header: one candidate fails, then the damaged frame.
  EXPECT_EQ(ft->stream_counters().crc_errors, 2u);
  EXPECT_EQ(ft->stream_counters().garbage_bytes, 8u + 16u);
  pty.write(frame(7));
  ASSERT_EQ(ft->read(r), HalStatus::ok);
  EXPECT_EQ(r.header.status_bits, 0u);
  const ft300::StreamParserCounters& c = ft->stream_counters();
  EXPECT_EQ(c.bytes, 16 * c.frames + c.garbage_bytes + 0u);
}

TEST_F(RobotiqFt300StreamTest, SilenceIsATimeout) {
  hal::WrenchReading r;
  tick(clock, 0.1);
  EXPECT_EQ(ft->read(r), HalStatus::no_data);
  tick(clock, 0.07);  // 0.17 s of silence > stream_timeout_s (0.16)
  EXPECT_EQ(ft->read(r), HalStatus::timeout);
  EXPECT_EQ(ft->read(r), HalStatus::timeout);
  EXPECT_EQ(ft->driver_counters().stream_timeouts, 2u);
  EXPECT_EQ(ft->counters().timeouts, 2u);
  pty.write(frame(1));
  EXPECT_EQ(ft->read(r), HalStatus::ok);
  EXPECT_EQ(ft->read(r), HalStatus::no_data);
}

TEST_F(RobotiqFt300StreamTest, TareSubtractsTheNextFrame) {
  hal::WrenchReading r;
  ft->request_tare();
  pty.write(frame(100, 200, 300, 40, 50, 60));
  ASSERT_EQ(ft->read(r), HalStatus::ok);
  for (double v : r.wrench) EXPECT_DOUBLE_EQ(v, 0.0);
  pty.write(frame(150, 200, 300, 40, 50, 60));
  ASSERT_EQ(ft->read(r), HalStatus::ok);
  EXPECT_NEAR(r.wrench[0], 0.5, 1e-12);
  EXPECT_NEAR(r.wrench[5], 0.0, 1e-12);
}

TEST_F(RobotiqFt300StreamTest, StopSendsTheJamSignal) {
  ASSERT_EQ(ft->stop(), HalStatus::ok);
  const std::vector<std::uint8_t> jam = pty.read(ft300::kJamLength);
  ASSERT_EQ(jam.size(), ft300::kJamLength);
  for (std::uint8_t b : jam) EXPECT_EQ(b, ft300::kJamByte);
  // start() again sends a new start request.
  ASSERT_EQ(ft->start(), HalStatus::ok);
  EXPECT_EQ(pty.read(ft300::kStartRequestSize).size(), ft300::kStartRequestSize);
  EXPECT_EQ(ft->driver_counters().stream_starts, 2u);
}

TEST_F(RobotiqFt300StreamTest, VanishedPortIsDisconnectedAndRetried) {
  hal::WrenchReading r;
  pty.write(frame(1));
  ASSERT_EQ(ft->read(r), HalStatus::ok);
  pty.close();  // the adapter is unplugged: the slave side hangs up
  EXPECT_EQ(ft->read(r), HalStatus::disconnected);
  EXPECT_EQ(ft->read(r), HalStatus::disconnected);  // within the interval: no attempt
  EXPECT_EQ(ft->driver_counters().reconnect_attempts, 0u);
  tick(clock, kPastReconnectS);
  EXPECT_EQ(ft->read(r), HalStatus::disconnected);  // the device node is gone
  EXPECT_EQ(ft->driver_counters().reconnect_attempts, 1u);
  EXPECT_EQ(ft->driver_counters().reconnects, 0u);
  EXPECT_EQ(ft->counters().disconnects, 1u);
  EXPECT_EQ(ft->counters().disconnected, 3u);
  EXPECT_EQ(ft->stop(), HalStatus::ok);  // nothing to jam: the port is closed
  EXPECT_EQ(ft->cleanup(), HalStatus::ok);
}

TEST(RobotiqFt300StreamConfigureTest, MissingDeviceIsDisconnected) {
  hal::ManualClock clock;
  RobotiqFt300Config c;
  c.mode = Ft300Mode::stream;
  c.link.device = "/nonexistent/ttyUSB7";
  RobotiqFt300 ft(clock, c);
  EXPECT_EQ(ft.configure(), HalStatus::disconnected);
}

}  // namespace
}  // namespace pliant::drivers::modbus
