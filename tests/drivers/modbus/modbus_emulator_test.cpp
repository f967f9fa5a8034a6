// The emulator as a server that others (HIL rigs) rely on: malformed requests and requests for
// another unit ID are counted and never stop it from serving the next client; start/stop rules.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdint>
#include <string>

#include "pliant/drivers/modbus/emulator/modbus_emulator.hpp"
#include "pliant/drivers/modbus/robotiq_ft300.hpp"

namespace pliant::drivers::modbus {
namespace {

using hal::HalStatus;

int connect_raw(std::uint16_t port) {
  const int s = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (s < 0 || ::connect(s, reinterpret_cast<const sockaddr*>(&a), sizeof a) != 0) {
    if (s >= 0) ::close(s);
    return -1;
  }
  return s;
}

// Reads until `want` bytes came, the server closed the socket or 2 s passed without a byte;
// returns the number of bytes read.
int read_answer(int s, std::uint8_t* buf, std::size_t want) {
  std::size_t got = 0;
  while (got < want) {
    pollfd p{s, POLLIN, 0};
    if (poll(&p, 1, 2000) != 1) break;
    const ssize_t n = ::recv(s, buf + got, want - got, 0);
    if (n <= 0) break;
    got += static_cast<std::size_t>(n);
  }
  return static_cast<int>(got);
}

RobotiqFt300Config ft_config(std::uint16_t port) {
  RobotiqFt300Config c;
  c.link.transport = ModbusTransport::tcp;
  c.link.port = port;
  c.link.response_timeout_s = 2.0;
  return c;
}

TEST(ModbusEmulatorTest, MalformedRequestsDoNotStopTheServer) {
  ModbusEmulator emulator;
  ASSERT_TRUE(emulator.start());
  // An MBAP header announcing a frame longer than any ADU, then noise.
  const int s = connect_raw(emulator.port());
  ASSERT_GE(s, 0);
  const std::uint8_t garbage[] = {0x00, 0x01, 0x00, 0x00, 0xff, 0xff, 0x09, 0x03, 0xff, 0xff, 0xff, 0xff,
                                  0x41, 0x42, 0x43, 0x44, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00};
  ASSERT_EQ(::send(s, garbage, sizeof garbage, MSG_NOSIGNAL), static_cast<ssize_t>(sizeof garbage));
  std::uint8_t buf[300];
  (void)read_answer(s, buf, 9);  // an exception answer (9 bytes) or a close: either is fine
  ::close(s);
  // Another client is served normally.
  hal::ManualClock clock;
  RobotiqFt300 ft(clock, ft_config(emulator.port()));
  ASSERT_EQ(ft.configure(), HalStatus::ok);
  ASSERT_EQ(ft.start(), HalStatus::ok);
  hal::WrenchReading r;
  EXPECT_EQ(ft.read(r), HalStatus::ok);
  EXPECT_GE(emulator.counters().connections, 2u);
}

TEST(ModbusEmulatorTest, OtherUnitIdGetsNoAnswer) {
  ModbusEmulator emulator;
  ASSERT_TRUE(emulator.start());
  const int s = connect_raw(emulator.port());
  ASSERT_GE(s, 0);
  // FC03 of registers 180..185 for unit 7: a well-formed request nobody here answers.
  const std::uint8_t request[] = {0x12, 0x34, 0x00, 0x00, 0x00, 0x06, 0x07, 0x03, 0x00, 0xb4, 0x00, 0x06};
  ASSERT_EQ(::send(s, request, sizeof request, MSG_NOSIGNAL), static_cast<ssize_t>(sizeof request));
  // The same request for unit 9 is answered: 9 + 2 * 6 bytes after the MBAP header.
  std::uint8_t ours[sizeof request];
  std::copy(request, request + sizeof request, ours);
  ours[6] = 0x09;
  ASSERT_EQ(::send(s, ours, sizeof ours, MSG_NOSIGNAL), static_cast<ssize_t>(sizeof ours));
  std::uint8_t buf[64];
  const int n = read_answer(s, buf, 7 + 2 + 12);
  ASSERT_EQ(n, 7 + 2 + 12);
  EXPECT_EQ(buf[6], 0x09);
  EXPECT_EQ(buf[7], 0x03);
  EXPECT_EQ(buf[8], 12);
  ::close(s);
  const ModbusEmulatorCounters c = emulator.counters();
  EXPECT_EQ(c.other_slave, 1u);
  EXPECT_EQ(c.requests, 1u);
  EXPECT_EQ(c.replies, 1u);
}

TEST(ModbusEmulatorTest, StartRules) {
  ModbusEmulatorConfig bad;
  bad.slave_id = 0;
  ModbusEmulator invalid(bad);
  std::string error;
  EXPECT_FALSE(invalid.start(&error));
  EXPECT_FALSE(error.empty());
  ModbusEmulator emulator;
  ASSERT_TRUE(emulator.start());
  EXPECT_NE(emulator.port(), 0);
  EXPECT_FALSE(emulator.start(&error));
  emulator.stop();
  emulator.stop();  // idempotent
  EXPECT_FALSE(emulator.disconnect_clients());
}

}  // namespace
}  // namespace pliant::drivers::modbus
