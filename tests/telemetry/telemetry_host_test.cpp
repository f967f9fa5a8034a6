// Host side of telemetry, in process: JSON lines field by field, recordings assembled from
// particle chunks (and read back with the recording reader), and the three transports on real
// descriptors: a file, a UDP socket on 127.0.0.1 and a pseudo-terminal pair (termios raw mode).
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdint>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "../support/temp_dir.hpp"
#include "pliant/host/recording.hpp"
#include "pliant/host/telemetry/json_lines.hpp"
#include "pliant/host/telemetry/recording_builder.hpp"
#include "pliant/host/telemetry/stream.hpp"
#include "pliant/host/telemetry/transports.hpp"
#include "telemetry_test_support.hpp"

namespace pliant::telemetry_test {
namespace {

namespace tm = host::telemetry;
using nlohmann::json;

// Decodes one frame and returns its JSON object.
json json_of(const Bytes& frame) {
  pliant_tm_decoder_t dec;
  pliant_tm_decoder_init(&dec);
  pliant_tm_message_t message;
  std::size_t used = 0;
  if (pliant_tm_decoder_push(&dec, frame.data(), frame.size(), &used, &message) != 1) {
    throw std::runtime_error("frame did not decode");
  }
  const std::string line = tm::message_json(message);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  return json::parse(line);
}

TEST(telemetry_json, Estimate) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 300);
  pliant_tm_estimate_t e = sample_estimate();
  e.msm_beta_std = kInf;
  e.flags = PLIANT_TM_ESTIMATE_VALID;
  const json j = json_of(estimate_frame(enc, 1234567890123ull, e));
  EXPECT_EQ(j.at("type"), "estimate");
  EXPECT_EQ(j.at("seq"), 300);
  EXPECT_EQ(j.at("stamp_us").get<std::uint64_t>(), 1234567890123ull);
  EXPECT_EQ(j.at("msm_beta").get<double>(), 0.375);
  EXPECT_TRUE(j.at("msm_beta_std").is_null());
  EXPECT_EQ(j.at("rms").get<double>(), 1.5e-4);
  EXPECT_EQ(j.at("frames"), 123456);
  EXPECT_EQ(j.at("unique_minimum"), false);
  EXPECT_EQ(j.at("valid"), true);
  EXPECT_EQ(j.size(), 9u);
}

TEST(telemetry_json, Verdict) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  pliant_tm_verdict_t v = sample_verdict();
  v.safe_width_m = kNaNf;
  v.predicted_force_n = -kInff;
  v.flags = PLIANT_TM_VERDICT_IN_CONTACT | PLIANT_TM_VERDICT_SLIP;
  v.fault_sources = 0x05;  // gripper, camera
  const json j = json_of(verdict_frame(enc, 5, v));
  EXPECT_EQ(j.at("type"), "verdict");
  EXPECT_EQ(j.at("verdict"), "limit");
  EXPECT_EQ(j.at("reason"), "force_limit");
  EXPECT_EQ(j.at("stop_action"), "open");
  EXPECT_EQ(j.at("fault_sources"), json({"gripper", "camera"}));
  EXPECT_EQ(j.at("reasons"), json({"stale_camera", "force_limit"}));
  EXPECT_EQ(j.at("in_contact"), true);
  EXPECT_EQ(j.at("slip"), true);
  // f32 values in their shortest form: 0.004f prints as 0.004, not 0.004000000189989805.
  EXPECT_EQ(j.at("closure_m").dump(), "0.004");
  EXPECT_EQ(j.at("force_n").get<double>(), 7.5);
  EXPECT_EQ(j.at("strain").dump(), "0.05");
  EXPECT_EQ(j.at("allowed_force_n").get<double>(), 7.0);
  EXPECT_EQ(j.at("predicted_strain").dump(), "0.06");
  EXPECT_EQ(j.at("safe_closure_m").dump(), "0.0035");
  EXPECT_TRUE(j.at("safe_width_m").is_null());
  EXPECT_TRUE(j.at("predicted_force_n").is_null());
  EXPECT_EQ(j.at("beta_low").get<double>(), 0.25);
  EXPECT_EQ(j.at("beta_high").get<double>(), 0.5);
  EXPECT_EQ(j.size(), 20u);
}

TEST(telemetry_json, VerdictOkAndStop) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  pliant_tm_verdict_t v = sample_verdict();
  v.verdict = 0;
  v.reason = 0;
  v.reasons = 0;
  v.fault_sources = 0;
  v.stop_action = 0;
  json j = json_of(verdict_frame(enc, 5, v));
  EXPECT_EQ(j.at("verdict"), "ok");
  EXPECT_EQ(j.at("reason"), "none");
  EXPECT_EQ(j.at("stop_action"), "freeze");
  EXPECT_EQ(j.at("reasons"), json::array());
  EXPECT_EQ(j.at("fault_sources"), json::array());
  v.verdict = 2;
  v.reason = 18;
  v.reasons = 1u << 18;
  v.fault_sources = 0x10;
  j = json_of(verdict_frame(enc, 5, v));
  EXPECT_EQ(j.at("verdict"), "stop");
  EXPECT_EQ(j.at("reason"), "estimate_uncertain");
  EXPECT_EQ(j.at("reasons"), json({"estimate_uncertain"}));
  EXPECT_EQ(j.at("fault_sources"), json({"clock"}));
}

TEST(telemetry_json, Particles) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  ParticleFrame f = make_particle_frame(9, 2, 12);
  f.positions[0] = kNaNf;
  const std::vector<Bytes> chunks = particle_chunks(enc, 77, f, 64);  // 4 particles per chunk
  ASSERT_EQ(chunks.size(), 3u);
  const json j = json_of(chunks[1]);
  EXPECT_EQ(j.at("type"), "particles");
  EXPECT_EQ(j.at("seq"), 1);
  EXPECT_EQ(j.at("frame"), 9);
  EXPECT_EQ(j.at("dim"), 2);
  EXPECT_EQ(j.at("total"), 12);
  EXPECT_EQ(j.at("first"), 4);
  EXPECT_EQ(j.at("count"), 4);
  ASSERT_EQ(j.at("positions").size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    ASSERT_EQ(j.at("positions")[i].size(), 2u);
    for (std::size_t axis = 0; axis < 2; ++axis) {
      EXPECT_EQ(static_cast<float>(j.at("positions")[i][axis].get<double>()), f.positions[(4 + i) * 2 + axis]);
    }
  }
  EXPECT_EQ(j.at("status"), json({"observed", "lost", "observed", "observed"}));  // ids 4..7
  const json first = json_of(chunks[0]);
  EXPECT_TRUE(first.at("positions")[0][0].is_null());
}

TEST(telemetry_json, Counters) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  const json j = json_of(counters_frame(enc, 1, {{8, 1000}, {14, 0}, {4242, 7}, {1, 4294967295u}}));
  EXPECT_EQ(j.at("type"), "counters");
  const json& c = j.at("counters");
  EXPECT_EQ(c.size(), 4u);
  EXPECT_EQ(c.at("guard_cycles"), 1000);
  EXPECT_EQ(c.at("telemetry_not_sent"), 0);
  EXPECT_EQ(c.at("4242"), 7);
  EXPECT_EQ(c.at("tracker_frames").get<std::uint64_t>(), 4294967295u);
}

// ---- recordings -----------------------------------------------------------------------------

void add_frame(tm::RecordingBuilder& builder, pliant_tm_encoder_t& enc, std::uint64_t stamp_us, const ParticleFrame& f,
               std::size_t capacity = 200, std::size_t skip_chunk = SIZE_MAX) {
  const std::vector<Bytes> chunks = particle_chunks(enc, stamp_us, f, capacity);
  for (std::size_t k = 0; k < chunks.size(); ++k) {
    if (k == skip_chunk) continue;
    pliant_tm_decoder_t dec;
    pliant_tm_decoder_init(&dec);
    pliant_tm_message_t message;
    std::size_t used = 0;
    ASSERT_EQ(pliant_tm_decoder_push(&dec, chunks[k].data(), chunks[k].size(), &used, &message), 1);
    builder.add(message.body.particles, message.header.stamp_us);
  }
}

TEST(telemetry_recording, FramesFromChunksReadBackWithTheRecordingReader) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  tm::RecordingBuilder builder;
  const ParticleFrame rest = make_particle_frame(0, 3, 40, true);
  ParticleFrame moved = make_particle_frame(1, 3, 40);  // some predicted, some lost
  moved.positions[3 * 2 + 1] = kNaNf;                   // observed but not finite: unobserved
  add_frame(builder, enc, 5'000'000, rest);
  add_frame(builder, enc, 5'033'333, moved);
  builder.finish();
  EXPECT_EQ(builder.counts().kept, 2u);
  EXPECT_EQ(builder.counts().dropped(), 0u);

  const test_support::TempDir dir("pliant_telemetry_");
  const std::string path = dir / "rec";
  host::write_recording(builder.recording("rec", "m"), path);
  const host::Recording r = host::read_recording(path);
  EXPECT_EQ(r.dimension, 3);
  EXPECT_EQ(r.particle_count, 40);
  EXPECT_EQ(r.length_unit, "m");
  ASSERT_EQ(r.frame_count(), 2);
  EXPECT_DOUBLE_EQ(r.frame_times_s[0], 5.0);
  EXPECT_DOUBLE_EQ(r.frame_times_s[1], 5.033333);
  for (int id = 0; id < 40; ++id) {
    for (int axis = 0; axis < 3; ++axis) {
      const auto k = static_cast<std::size_t>(id * 3 + axis);
      EXPECT_EQ(static_cast<float>(r.position(0, id, axis)), rest.positions[k]);
      EXPECT_EQ(static_cast<float>(r.rest_positions[k]), rest.positions[k]);
    }
    const bool seen = moved.status[static_cast<std::size_t>(id)] == PLIANT_TM_OBSERVED && id != 2;
    EXPECT_EQ(r.observed(1, id), seen) << id;
    if (seen) {
      EXPECT_EQ(static_cast<float>(r.position(1, id, 2)), moved.positions[static_cast<std::size_t>(id * 3 + 2)]);
    }
  }
  EXPECT_EQ(r.meta.at("source"), "pliant telemetry");
}

TEST(telemetry_recording, EveryUnusableFrameCountedOnce) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  tm::RecordingBuilder builder;
  add_frame(builder, enc, 1000, make_particle_frame(0, 2, 30));          // predicted particles: before_rest
  add_frame(builder, enc, 2000, make_particle_frame(1, 2, 30, true));    // kept: the rest shape
  add_frame(builder, enc, 3000, make_particle_frame(2, 2, 30), 200, 1);  // a chunk lost: incomplete
  add_frame(builder, enc, 2000, make_particle_frame(3, 2, 30));          // stamp of the last kept: time
  add_frame(builder, enc, 4000, make_particle_frame(4, 3, 30));          // other dimension: shape
  add_frame(builder, enc, 5000, make_particle_frame(5, 2, 31));          // other count: shape
  add_frame(builder, enc, 6000, make_particle_frame(6, 2, 30));          // kept
  // A frame whose second chunk repeats the first: overlapping, incomplete.
  {
    const ParticleFrame f = make_particle_frame(7, 2, 30);
    const std::vector<Bytes> chunks = particle_chunks(enc, 7000, f, 200);
    ASSERT_EQ(chunks.size(), 2u);
    for (const Bytes* chunk : {&chunks[0], &chunks[0], &chunks[1]}) {
      pliant_tm_decoder_t dec;
      pliant_tm_decoder_init(&dec);
      pliant_tm_message_t m;
      std::size_t used = 0;
      ASSERT_EQ(pliant_tm_decoder_push(&dec, chunk->data(), chunk->size(), &used, &m), 1);
      builder.add(m.body.particles, m.header.stamp_us);
    }
  }
  add_frame(builder, enc, 8000, make_particle_frame(8, 2, 30), 200, 1);  // cut at the end: incomplete
  builder.finish();
  const tm::ParticleFrameCounts& c = builder.counts();
  EXPECT_EQ(c.kept, 2u);
  EXPECT_EQ(c.before_rest, 1u);
  EXPECT_EQ(c.incomplete, 3u);
  EXPECT_EQ(c.time, 1u);
  EXPECT_EQ(c.shape, 2u);
  const host::Recording r = builder.recording("x", "px");
  EXPECT_EQ(r.frame_count(), 2);
  EXPECT_EQ(r.length_unit, "px");
}

TEST(telemetry_recording, NothingKeptThrows) {
  tm::RecordingBuilder builder;
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  add_frame(builder, enc, 1, make_particle_frame(0, 3, 0));  // no particles
  builder.finish();
  EXPECT_FALSE(builder.has_frames());
  EXPECT_EQ(builder.counts().shape, 1u);
  EXPECT_THROW(builder.recording("x", "m"), std::runtime_error);
}

// ---- transports and the read loop ------------------------------------------------------------

Bytes sample_stream(std::size_t* messages) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  Bytes stream;
  std::size_t n = 0;
  for (std::uint64_t k = 0; k < 5; ++k) {
    append(stream, estimate_frame(enc, k, sample_estimate()));
    append(stream, verdict_frame(enc, k, sample_verdict()));
    for (const Bytes& chunk : particle_chunks(enc, k, make_particle_frame(static_cast<std::uint32_t>(k), 3, 100))) {
      append(stream, chunk);
      ++n;
    }
    n += 2;
  }
  // Bytes a terminal in cooked mode would eat or change: ^C (signal), ^D (end of file), ^Q/^S
  // (flow control), CR (to NL), DEL and ^U (line editing), ^Z (suspend).
  append(stream, counters_frame(enc, 9, {{0x1517, 0x1113030Du}, {0x1A04, 0x7F0A0D03u}, {0x0D0A, 0x13111A04u}}));
  *messages = n + 1;
  return stream;
}

void check_stream_result(const tm::StreamResult& r, std::size_t messages) {
  EXPECT_EQ(r.messages.total(), messages);
  EXPECT_EQ(r.messages.estimate, 5u);
  EXPECT_EQ(r.messages.verdict, 5u);
  EXPECT_EQ(r.messages.counters, 1u);
  EXPECT_EQ(r.dropped(), 0u) << tm::stream_summary(r);
  EXPECT_EQ(r.decoder.seq_missed, 0u);
}

TEST(telemetry_transport, FileToTheEnd) {
  std::size_t messages = 0;
  const Bytes stream = sample_stream(&messages);
  const test_support::TempDir dir("pliant_telemetry_");
  const std::string path = dir / "capture.bin";
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(stream.data()), static_cast<std::streamsize>(stream.size()));
  tm::FileSource file(path);
  EXPECT_EQ(file.describe(), path);
  std::vector<std::string> lines;
  const tm::StreamResult r =
      tm::read_telemetry(file, {}, [&](const pliant_tm_message_t& m) { lines.push_back(tm::message_json(m)); });
  EXPECT_EQ(r.end, tm::StreamEnd::end_of_input);
  EXPECT_EQ(r.bytes, stream.size());
  check_stream_result(r, messages);
  EXPECT_EQ(lines.size(), messages);
  const json last = json::parse(lines.back());
  EXPECT_EQ(last.at("counters").at("5399").get<std::uint32_t>(), 0x1113030Du);
  const std::string summary = tm::stream_summary(r);
  EXPECT_NE(summary.find("messages " + std::to_string(messages) + " (estimate 5, verdict 5"), std::string::npos)
      << summary;
  EXPECT_NE(summary.find("dropped 0 (cobs_error 0"), std::string::npos) << summary;
  EXPECT_NE(summary.find("end of input"), std::string::npos) << summary;
}

TEST(telemetry_transport, CountStopsRightAfterTheMessage) {
  std::size_t messages = 0;
  const Bytes stream = sample_stream(&messages);
  const test_support::TempDir dir("pliant_telemetry_");
  const std::string path = dir / "capture.bin";
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(stream.data()), static_cast<std::streamsize>(stream.size()));
  tm::FileSource file(path);
  tm::StreamLimits limits;
  limits.max_messages = 4;
  std::size_t seen = 0;
  const tm::StreamResult r = tm::read_telemetry(file, limits, [&](const pliant_tm_message_t&) { ++seen; });
  EXPECT_EQ(r.end, tm::StreamEnd::count);
  EXPECT_EQ(seen, 4u);
  EXPECT_EQ(r.decoder.truncated, 0u) << "the count ends on a delimiter";
}

// Gives its chunks, then fails.
class FailingSource final : public tm::ByteSource {
 public:
  explicit FailingSource(Bytes bytes) : bytes_(std::move(bytes)) {}
  tm::ReadResult read(std::uint8_t* buffer, std::size_t capacity, int) override {
    if (at_ >= bytes_.size()) throw std::runtime_error("scripted: read failed: Input/output error");
    const std::size_t n = std::min<std::size_t>({capacity, bytes_.size() - at_, 10});
    std::copy(bytes_.begin() + static_cast<std::ptrdiff_t>(at_), bytes_.begin() + static_cast<std::ptrdiff_t>(at_ + n),
              buffer);
    at_ += n;
    return {tm::ReadStatus::data, n};
  }
  std::string describe() const override { return "scripted"; }

 private:
  Bytes bytes_;
  std::size_t at_ = 0;
};

TEST(telemetry_transport, ReadErrorEndsTheStreamWithWhatWasDecoded) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  Bytes stream = estimate_frame(enc, 1, sample_estimate());
  const Bytes second = verdict_frame(enc, 2, sample_verdict());
  stream.insert(stream.end(), second.begin(), second.begin() + 20);  // cut by the failure
  FailingSource source(stream);
  std::size_t seen = 0;
  const tm::StreamResult r = tm::read_telemetry(source, {}, [&](const pliant_tm_message_t&) { ++seen; });
  EXPECT_EQ(r.end, tm::StreamEnd::read_error);
  EXPECT_EQ(r.error, "scripted: read failed: Input/output error");
  EXPECT_EQ(seen, 1u);
  EXPECT_EQ(r.decoder.truncated, 1u);
}

// ---- UDP ----

class Sender {
 public:
  Sender() : fd_(::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0)) {
    if (fd_ < 0) throw std::runtime_error("socket");
  }
  ~Sender() { ::close(fd_); }
  void send(int port, const std::uint8_t* data, std::size_t size) const {
    sockaddr_in to{};
    to.sin_family = AF_INET;
    to.sin_port = htons(static_cast<std::uint16_t>(port));
    to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    if (::sendto(fd_, data, size, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to) != static_cast<ssize_t>(size)) {
      throw std::runtime_error("sendto");
    }
  }

 private:
  int fd_;
};

TEST(telemetry_transport, UdpDatagramsOnLoopback) {
  std::size_t messages = 0;
  const Bytes stream = sample_stream(&messages);
  tm::UdpSource udp("127.0.0.1", 0);
  ASSERT_GT(udp.port(), 0);
  EXPECT_EQ(udp.describe(), "udp 127.0.0.1:" + std::to_string(udp.port()));
  // Datagrams of 700 bytes: frames split across datagrams and several frames in one.
  const Sender sender;
  for (std::size_t at = 0; at < stream.size(); at += 700) {
    sender.send(udp.port(), stream.data() + at, std::min<std::size_t>(700, stream.size() - at));
  }
  tm::StreamLimits limits;
  limits.max_messages = messages;
  limits.max_duration_s = 10;
  const tm::StreamResult r = tm::read_telemetry(udp, limits, [](const pliant_tm_message_t&) {});
  EXPECT_EQ(r.end, tm::StreamEnd::count);
  check_stream_result(r, messages);
}

TEST(telemetry_transport, DurationBoundsASilentSource) {
  tm::UdpSource udp("127.0.0.1", 0);
  tm::StreamLimits limits;
  limits.max_duration_s = 0.3;
  const auto start = std::chrono::steady_clock::now();
  const tm::StreamResult r = tm::read_telemetry(udp, limits, [](const pliant_tm_message_t&) {});
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(r.end, tm::StreamEnd::duration);
  EXPECT_GE(took, 0.29);
  EXPECT_LT(took, 2.0);
  EXPECT_EQ(r.messages.total(), 0u);
}

TEST(telemetry_transport, StopRequestEndsTheStream) {
  tm::UdpSource udp("127.0.0.1", 0);
  const auto start = std::chrono::steady_clock::now();
  const auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  const tm::StreamResult r = tm::read_telemetry(
      udp, {}, [](const pliant_tm_message_t&) {}, [&] { return elapsed() > 0.2; });
  EXPECT_EQ(r.end, tm::StreamEnd::stopped);
  EXPECT_LT(elapsed(), 2.0);
}

TEST(telemetry_transport, UdpRefusals) {
  EXPECT_THROW(tm::UdpSource("localhost", 0), std::invalid_argument);
  EXPECT_THROW(tm::UdpSource("127.0.0.1", 70000), std::invalid_argument);
  EXPECT_THROW(tm::UdpSource("127.0.0.1", -1), std::invalid_argument);
  tm::UdpSource first("127.0.0.1", 0);
  try {
    tm::UdpSource second("127.0.0.1", first.port());
    ADD_FAILURE() << "bound the same port twice";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("cannot bind"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(std::to_string(first.port())), std::string::npos) << e.what();
  }
}

// ---- serial, through a pseudo-terminal pair ----

struct PseudoTerminal {
  int master = -1;
  std::string slave;
  PseudoTerminal() {
    master = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
    if (master < 0 || ::grantpt(master) != 0 || ::unlockpt(master) != 0) throw std::runtime_error("posix_openpt");
    slave = ::ptsname(master);
  }
  ~PseudoTerminal() { close(); }
  void close() {
    if (master >= 0) ::close(master);
    master = -1;
  }
  PseudoTerminal(const PseudoTerminal&) = delete;
  PseudoTerminal& operator=(const PseudoTerminal&) = delete;
};

void write_all(int fd, const Bytes& bytes) {
  std::size_t at = 0;
  while (at < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + at, std::min<std::size_t>(bytes.size() - at, 333));
    if (n < 0) {
      if (errno == EINTR || errno == EAGAIN) continue;
      throw std::runtime_error("write to the pseudo-terminal failed");
    }
    at += static_cast<std::size_t>(n);
  }
}

TEST(telemetry_transport, SerialPortIsRawAndDecodes) {
  const PseudoTerminal pty;
  tm::SerialSource serial(pty.slave, 921600);
  EXPECT_EQ(serial.describe(), pty.slave + " at 921600 baud");
  {
    // The settings really applied to the device.
    const int fd = ::open(pty.slave.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    ASSERT_GE(fd, 0);
    termios t{};
    ASSERT_EQ(::tcgetattr(fd, &t), 0);
    ::close(fd);
    EXPECT_EQ(t.c_lflag & (ICANON | ECHO | ISIG | IEXTEN), 0u);
    EXPECT_EQ(t.c_iflag & (ICRNL | INLCR | IGNCR | IXON | IXOFF | ISTRIP), 0u);
    EXPECT_EQ(t.c_oflag & OPOST, 0u);
    EXPECT_EQ(t.c_cflag & CSIZE, static_cast<tcflag_t>(CS8));
    EXPECT_EQ(t.c_cflag & (PARENB | CSTOPB), 0u);
    EXPECT_EQ(::cfgetispeed(&t), static_cast<speed_t>(B921600));
  }
  std::size_t messages = 0;
  const Bytes stream = sample_stream(&messages);
  std::thread writer([&] { write_all(pty.master, stream); });
  tm::StreamLimits limits;
  limits.max_messages = messages;
  limits.max_duration_s = 10;
  std::vector<std::string> lines;
  const tm::StreamResult r =
      tm::read_telemetry(serial, limits, [&](const pliant_tm_message_t& m) { lines.push_back(tm::message_json(m)); });
  writer.join();
  EXPECT_EQ(r.end, tm::StreamEnd::count);
  check_stream_result(r, messages);
  ASSERT_FALSE(lines.empty());
  const json last = json::parse(lines.back());
  EXPECT_EQ(last.at("counters").at("5399").get<std::uint32_t>(), 0x1113030Du);
  EXPECT_EQ(last.at("counters").at("6660").get<std::uint32_t>(), 0x7F0A0D03u);
  EXPECT_EQ(last.at("counters").at("3338").get<std::uint32_t>(), 0x13111A04u);
}

TEST(telemetry_transport, SerialHangupEndsTheStream) {
  PseudoTerminal pty;
  tm::SerialSource serial(pty.slave);
  EXPECT_EQ(serial.describe(), pty.slave + " at 115200 baud");
  pty.close();
  tm::StreamLimits limits;
  limits.max_duration_s = 5;
  const tm::StreamResult r = tm::read_telemetry(serial, limits, [](const pliant_tm_message_t&) {});
  EXPECT_EQ(r.end, tm::StreamEnd::hangup);
  EXPECT_LT(r.elapsed_s, 2.0);
}

TEST(telemetry_transport, OpeningRefusals) {
  const PseudoTerminal pty;
  EXPECT_THROW(tm::SerialSource(pty.slave, 12345), std::invalid_argument);
  try {
    tm::SerialSource("/dev/null");
    ADD_FAILURE() << "/dev/null accepted as a serial port";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "/dev/null: not a serial port (no terminal attributes)");
  }
  try {
    tm::SerialSource("/nonexistent/ttyX");
    ADD_FAILURE();
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/ttyX: cannot open: No such file or directory");
  }
  const test_support::TempDir dir("pliant_telemetry_");
  EXPECT_THROW(tm::FileSource(dir.path().string()), std::runtime_error);
  EXPECT_THROW(tm::FileSource(dir / "missing.bin"), std::runtime_error);
  EXPECT_EQ(tm::FileSource("-").describe(), "standard input");
  EXPECT_EQ(tm::supported_baud_rates().front(), 1200);
  EXPECT_EQ(tm::supported_baud_rates().back(), 4000000);
}
}  // namespace
}  // namespace pliant::telemetry_test
