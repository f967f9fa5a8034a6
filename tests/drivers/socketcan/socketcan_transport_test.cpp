// The AF_UNIX SOCK_SEQPACKET transport: frame boundaries, non-blocking receive, receive
// timestamps, malformed records, a closed peer, the named listener and reconnects.
#include <gtest/gtest.h>

#include <linux/can.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cstring>
#include <string>

#include "pliant/drivers/socketcan/can_error.hpp"
#include "pliant/drivers/socketcan/seqpacket_transport.hpp"
#include "socketcan_fixture.hpp"
#include "support/temp_dir.hpp"

namespace pliant::drivers::socketcan {
namespace {

using hal::HalStatus;

std::int64_t realtime_ns() {
  timespec ts{};
  ::clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1000000000 + ts.tv_nsec;
}

CanFrame sample_frame() {
  const std::uint8_t payload[6] = {0xff, 0x38, 0x00, 0x32, 0x00, 0x14};
  return make_standard_frame(0x201, payload, 6);
}

TEST(SocketCanSeqpacket, FramesKeepTheirBoundariesAndTimestamps) {
  SeqpacketCanTransport a, b;
  ASSERT_EQ(SeqpacketCanTransport::make_pair(a, b), HalStatus::ok);
  CanFrame f;
  CanRxInfo info;
  EXPECT_EQ(b.receive(f, info), CanIo::empty);  // non-blocking
  const std::int64_t before = realtime_ns();
  ASSERT_EQ(a.send(sample_frame()), CanIo::ok);
  ASSERT_EQ(a.send(make_can_error_frame(kCanErrBusOff, nullptr)), CanIo::ok);
  ASSERT_EQ(b.receive(f, info), CanIo::ok);
  const std::int64_t after = realtime_ns();
  EXPECT_EQ(f.id, 0x201u);
  ASSERT_EQ(f.dlc, 6);
  EXPECT_EQ(f.data[0], 0xff);
  EXPECT_EQ(f.data[5], 0x14);
  EXPECT_EQ(f.data[6], 0);  // beyond dlc: zero
  // SO_TIMESTAMP has microsecond resolution: allow one microsecond of truncation.
  EXPECT_GE(info.realtime_ns, before - 1000);
  EXPECT_LE(info.realtime_ns, after);
  ASSERT_EQ(b.receive(f, info), CanIo::ok);
  EXPECT_TRUE(is_error_frame(f));
  EXPECT_EQ(f.dlc, 8);
  EXPECT_EQ(b.receive(f, info), CanIo::empty);
  // The same in the other direction.
  ASSERT_EQ(b.send(sample_frame()), CanIo::ok);
  EXPECT_EQ(a.receive(f, info), CanIo::ok);
}

TEST(SocketCanSeqpacket, MalformedRecordsAreConsumedOneByOne) {
  SeqpacketCanTransport a, b;
  ASSERT_EQ(SeqpacketCanTransport::make_pair(a, b), HalStatus::ok);
  const unsigned char shortrec[7] = {1, 2, 3, 4, 5, 6, 7};
  unsigned char longrec[40] = {};
  struct can_frame bad_len {};
  bad_len.can_id = 0x201;
  bad_len.len = 9;
  ASSERT_EQ(a.send_record(shortrec, sizeof shortrec), CanIo::ok);
  ASSERT_EQ(a.send_record(longrec, sizeof longrec), CanIo::ok);
  ASSERT_EQ(a.send_record(&bad_len, sizeof bad_len), CanIo::ok);
  ASSERT_EQ(a.send_record(longrec, 17), CanIo::ok);
  ASSERT_EQ(a.send(sample_frame()), CanIo::ok);
  CanFrame f;
  CanRxInfo info;
  EXPECT_EQ(b.receive(f, info), CanIo::malformed);
  EXPECT_EQ(b.receive(f, info), CanIo::malformed);
  EXPECT_EQ(b.receive(f, info), CanIo::malformed);
  EXPECT_EQ(b.receive(f, info), CanIo::malformed);
  ASSERT_EQ(b.receive(f, info), CanIo::ok);
  EXPECT_EQ(f.id, 0x201u);
  EXPECT_TRUE(b.is_open());
}

TEST(SocketCanSeqpacket, ClosedPeerIsDisconnectedWithoutSigpipe) {
  SeqpacketCanTransport a, b;
  ASSERT_EQ(SeqpacketCanTransport::make_pair(a, b), HalStatus::ok);
  ASSERT_EQ(a.send(sample_frame()), CanIo::ok);
  b.close();
  // a's queued frame went with b; a now sees the peer gone, on send (EPIPE, no signal) ...
  EXPECT_EQ(a.send(sample_frame()), CanIo::disconnected);
  EXPECT_FALSE(a.is_open());
  EXPECT_EQ(a.open(), HalStatus::disconnected);  // a socketpair end cannot reconnect
  // ... and on receive (end of stream), after the frames still queued.
  SeqpacketCanTransport c, d;
  ASSERT_EQ(SeqpacketCanTransport::make_pair(c, d), HalStatus::ok);
  ASSERT_EQ(d.send(sample_frame()), CanIo::ok);
  d.close();
  CanFrame f;
  CanRxInfo info;
  EXPECT_EQ(c.receive(f, info), CanIo::ok);
  EXPECT_EQ(c.receive(f, info), CanIo::disconnected);
  EXPECT_FALSE(c.is_open());
  EXPECT_EQ(c.receive(f, info), CanIo::disconnected);
  EXPECT_EQ(c.send(f), CanIo::disconnected);
}

TEST(SocketCanSeqpacket, FullBufferIsBusyNotBlocking) {
  SeqpacketCanTransport a, b;
  ASSERT_EQ(SeqpacketCanTransport::make_pair(a, b), HalStatus::ok);
  CanIo io = CanIo::ok;
  int sent = 0;
  for (; sent < 100000 && io == CanIo::ok; ++sent) io = a.send(sample_frame());
  EXPECT_EQ(io, CanIo::busy);
  EXPECT_GT(sent, 1);
  // Draining one record makes room again.
  CanFrame f;
  CanRxInfo info;
  for (int i = 0; i < 64; ++i) ASSERT_EQ(b.receive(f, info), CanIo::ok);
  EXPECT_EQ(a.send(sample_frame()), CanIo::ok);
}

TEST(SocketCanSeqpacket, ListenerAcceptsAndClientReconnects) {
  const std::string address = test::unique_address("listen");
  SeqpacketCanTransport client;
  ASSERT_EQ(client.set_address(address.c_str()), HalStatus::ok);
  EXPECT_EQ(client.open(), HalStatus::disconnected);  // nobody listening yet
  SeqpacketCanListener listener;
  ASSERT_EQ(listener.listen(address.c_str()), HalStatus::ok);
  SeqpacketCanTransport server;
  EXPECT_EQ(listener.accept(server), HalStatus::no_data);
  ASSERT_EQ(client.open(), HalStatus::ok);
  ASSERT_EQ(listener.accept(server), HalStatus::ok);
  ASSERT_EQ(client.send(sample_frame()), CanIo::ok);
  CanFrame f;
  CanRxInfo info;
  ASSERT_EQ(server.receive(f, info), CanIo::ok);
  EXPECT_EQ(f.id, 0x201u);
  server.close();
  EXPECT_EQ(client.receive(f, info), CanIo::disconnected);
  ASSERT_EQ(client.open(), HalStatus::ok);  // same address, new connection
  SeqpacketCanTransport server2;
  ASSERT_EQ(listener.accept(server2), HalStatus::ok);
  ASSERT_EQ(server2.send(sample_frame()), CanIo::ok);
  EXPECT_EQ(client.receive(f, info), CanIo::ok);
}

TEST(SocketCanSeqpacket, FilesystemListenerRemovesItsSocketFile) {
  pliant::test_support::TempDir dir("pliant_socketcan_");
  const std::string path = dir / "can.sock";
  {
    SeqpacketCanListener listener;
    ASSERT_EQ(listener.listen(path.c_str()), HalStatus::ok);
    EXPECT_EQ(::access(path.c_str(), F_OK), 0);
    SeqpacketCanListener second;
    EXPECT_EQ(second.listen(path.c_str()), HalStatus::io_error);  // EADDRINUSE, nothing replaced
    SeqpacketCanTransport client, server;
    ASSERT_EQ(client.set_address(path.c_str()), HalStatus::ok);
    ASSERT_EQ(client.open(), HalStatus::ok);
    ASSERT_EQ(listener.accept(server), HalStatus::ok);
  }
  EXPECT_NE(::access(path.c_str(), F_OK), 0);
}

TEST(SocketCanSeqpacket, BadAddressesAndFiltersAreRefused) {
  SeqpacketCanTransport t;
  EXPECT_EQ(t.open(), HalStatus::disconnected);  // no address
  EXPECT_EQ(t.set_address(""), HalStatus::invalid_argument);
  EXPECT_EQ(t.set_address("@"), HalStatus::invalid_argument);
  EXPECT_EQ(t.set_address(nullptr), HalStatus::invalid_argument);
  const std::string too_long(200, 'x');
  EXPECT_EQ(t.set_address(too_long.c_str()), HalStatus::invalid_argument);
  SeqpacketCanListener l;
  EXPECT_EQ(l.listen(""), HalStatus::invalid_argument);
  EXPECT_EQ(l.accept(t), HalStatus::io_error);  // not listening
  std::uint32_t ids[kMaxCanFilterIds + 1] = {};
  EXPECT_EQ(t.set_receive_filter(ids, kMaxCanFilterIds + 1), HalStatus::invalid_argument);
  ids[0] = 0x800;
  EXPECT_EQ(t.set_receive_filter(ids, 1), HalStatus::invalid_argument);
  ids[0] = 0x7ff;
  EXPECT_EQ(t.set_receive_filter(ids, 1), HalStatus::ok);
  EXPECT_EQ(t.filter_count(), 1u);
  EXPECT_EQ(t.adopt(-1), HalStatus::io_error);
  EXPECT_STREQ(can_io_name(CanIo::busy), "busy");
}

}  // namespace
}  // namespace pliant::drivers::socketcan
