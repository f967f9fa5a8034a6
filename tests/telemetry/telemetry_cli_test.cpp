// `pliant telemetry`: runs the built binary on captured streams (file, standard input), live
// UDP datagrams on 127.0.0.1 and a pseudo-terminal serial port, and checks exit statuses, the
// JSON lines field by field, the stderr summary, and recordings read back with the reader.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "../cli/cli_test_support.hpp"
#include "pliant/host/recording.hpp"
#include "telemetry_test_support.hpp"

extern char** environ;

namespace pliant::telemetry_test {
namespace {

using cli_test::CommandResult;
using cli_test::quoted;
using cli_test::read_text;
using cli_test::run_pliant;
using nlohmann::json;
namespace fs = std::filesystem;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

void write_bytes(const fs::path& path, const Bytes& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw std::runtime_error("cannot write " + path.string());
}

std::vector<json> json_lines(const std::string& text) {
  std::vector<json> out;
  for (const std::string& line : cli_test::lines_of(text)) out.push_back(json::parse(line));
  return out;
}

// Runs `pliant telemetry ...` through the shell, with `input` redirected to standard input.
CommandResult run_with_input(const std::string& arguments, const std::string& input) {
  const cli_test::TempDir capture;
  const std::string out = capture / "stdout";
  const std::string err = capture / "stderr";
  const std::string command =
      quoted(PLIANT_EXE) + " " + arguments + " <" + quoted(input) + " >" + quoted(out) + " 2>" + quoted(err);
  const int raw = std::system(command.c_str());
  CommandResult result;
  result.status = raw != -1 && WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  result.out = read_text(out);
  result.err = read_text(err);
  return result;
}

// One estimate, one verdict, a 3D frame of 100 particles in two chunks, one counters message.
Bytes small_stream() {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 500);
  Bytes stream = estimate_frame(enc, 1000, sample_estimate());
  pliant_tm_verdict_t v = sample_verdict();
  v.safe_width_m = kNaNf;
  append(stream, verdict_frame(enc, 2000, v));
  for (const Bytes& chunk : particle_chunks(enc, 3000, make_particle_frame(7, 3, 100))) append(stream, chunk);
  append(stream, counters_frame(enc, 4000, {{8, 1000}, {4242, 7}}));
  return stream;
}

// Particle frames 0..frames-1 (the first observing every particle), 2D, 30 particles, chunks of
// at most 200 bytes (2 per frame), 33 ms apart, with an estimate between frames.
Bytes recording_stream(std::uint32_t frames) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  Bytes stream;
  for (std::uint32_t k = 0; k < frames; ++k) {
    const std::uint64_t stamp = 10'000'000 + 33'000ull * k;
    for (const Bytes& chunk : particle_chunks(enc, stamp, make_particle_frame(k, 2, 30, k == 0), 200)) {
      append(stream, chunk);
    }
    append(stream, estimate_frame(enc, stamp, sample_estimate()));
  }
  return stream;
}

TEST(telemetry_cli, HelpExplainsTheCommand) {
  const CommandResult r = run_pliant("telemetry --help");
  EXPECT_EQ(r.status, 0);
  for (const char* part :
       {"--serial", "--baud", "--udp", "--bind", "--file", "-o,--output", "--recording", "--length-unit", "--count",
        "--duration", "docs/telemetry.md", "Exit status", "JSON", "SIGINT"}) {
    EXPECT_TRUE(contains(r.out, part)) << part << " in\n" << r.out;
  }
  EXPECT_TRUE(contains(run_pliant("--help").out, "telemetry"));
}

TEST(telemetry_cli, FileToJsonLinesFieldByField) {
  const cli_test::TempDir dir;
  write_bytes(dir.path() / "capture.bin", small_stream());
  const CommandResult r = run_pliant("telemetry --file " + quoted(dir / "capture.bin"));
  EXPECT_EQ(r.status, 0) << r.err;
  const std::vector<json> lines = json_lines(r.out);
  ASSERT_EQ(lines.size(), 5u);

  const json& e = lines[0];
  EXPECT_EQ(e.at("type"), "estimate");
  EXPECT_EQ(e.at("seq"), 500);
  EXPECT_EQ(e.at("stamp_us"), 1000);
  EXPECT_EQ(e.at("msm_beta").get<double>(), 0.375);
  EXPECT_EQ(e.at("msm_beta_std").get<double>(), 0.0625);
  EXPECT_EQ(e.at("rms").get<double>(), 1.5e-4);
  EXPECT_EQ(e.at("frames"), 123456);
  EXPECT_EQ(e.at("unique_minimum"), true);
  EXPECT_EQ(e.at("valid"), true);

  const json& v = lines[1];
  EXPECT_EQ(v.at("type"), "verdict");
  EXPECT_EQ(v.at("seq"), 501);
  EXPECT_EQ(v.at("stamp_us"), 2000);
  EXPECT_EQ(v.at("verdict"), "limit");
  EXPECT_EQ(v.at("reason"), "force_limit");
  EXPECT_EQ(v.at("stop_action"), "open");
  EXPECT_EQ(v.at("fault_sources"), json({"camera"}));
  EXPECT_EQ(v.at("reasons"), json({"stale_camera", "force_limit"}));
  EXPECT_EQ(v.at("in_contact"), true);
  EXPECT_EQ(v.at("slip"), false);
  EXPECT_EQ(v.at("closure_m").dump(), "0.004");
  EXPECT_EQ(v.at("force_n").get<double>(), 7.5);
  EXPECT_EQ(v.at("allowed_force_n").get<double>(), 7.0);
  EXPECT_EQ(v.at("safe_closure_m").dump(), "0.0035");
  EXPECT_TRUE(v.at("safe_width_m").is_null());
  EXPECT_EQ(v.at("predicted_force_n").dump(), "6.9");
  EXPECT_EQ(v.at("beta_low").get<double>(), 0.25);
  EXPECT_EQ(v.at("beta_high").get<double>(), 0.5);

  const ParticleFrame f = make_particle_frame(7, 3, 100);
  std::size_t particles = 0;
  for (std::size_t k = 2; k < 4; ++k) {
    const json& p = lines[k];
    EXPECT_EQ(p.at("type"), "particles");
    EXPECT_EQ(p.at("frame"), 7);
    EXPECT_EQ(p.at("dim"), 3);
    EXPECT_EQ(p.at("total"), 100);
    EXPECT_EQ(p.at("first").get<std::size_t>(), particles);
    const std::size_t count = p.at("count").get<std::size_t>();
    ASSERT_EQ(p.at("positions").size(), count);
    ASSERT_EQ(p.at("status").size(), count);
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t id = particles + i;
      for (std::size_t axis = 0; axis < 3; ++axis) {
        EXPECT_EQ(static_cast<float>(p.at("positions")[i][axis].get<double>()), f.positions[id * 3 + axis]) << id;
      }
      const char* status = f.status[id] == PLIANT_TM_OBSERVED    ? "observed"
                           : f.status[id] == PLIANT_TM_PREDICTED ? "predicted"
                                                                 : "lost";
      EXPECT_EQ(p.at("status")[i], status) << id;
    }
    particles += count;
  }
  EXPECT_EQ(particles, 100u);

  const json& c = lines[4];
  EXPECT_EQ(c.at("type"), "counters");
  EXPECT_EQ(c.at("counters"), json({{"guard_cycles", 1000}, {"4242", 7}}));

  // One summary line on stderr.
  ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_EQ(r.err_lines()[0].rfind("pliant telemetry: messages 5 (estimate 1, verdict 1, particles 2, counters 1); "
                                   "dropped 0 (cobs_error 0, crc_mismatch 0, oversize 0, short_packet 0, version 0, "
                                   "bad_length 0, out_of_range 0, unknown_type 0, truncated 0); sequence: 0 missed, 0 "
                                   "backward; ",
                                   0),
            0u)
      << r.err;
  EXPECT_TRUE(contains(r.err, "end of input")) << r.err;
}

TEST(telemetry_cli, OutputFileAppearsWhole) {
  const cli_test::TempDir dir;
  write_bytes(dir.path() / "capture.bin", small_stream());
  const std::string out = dir / "out.jsonl";
  const CommandResult r = run_pliant("telemetry --file " + quoted(dir / "capture.bin") + " -o " + quoted(out));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(json_lines(read_text(out)).size(), 5u);
  EXPECT_TRUE(contains(r.err, "; wrote " + out)) << r.err;
  std::size_t files = 0;
  for (const auto& entry : fs::directory_iterator(dir.path())) files += entry.is_regular_file() ? 1u : 0u;
  EXPECT_EQ(files, 2u) << "no temporary file left";
}

TEST(telemetry_cli, StandardInputAndCount) {
  const cli_test::TempDir dir;
  write_bytes(dir.path() / "capture.bin", small_stream());
  CommandResult r = run_with_input("telemetry --file -", dir / "capture.bin");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(json_lines(r.out).size(), 5u);
  r = run_with_input("telemetry --file - --count 2", dir / "capture.bin");
  EXPECT_EQ(r.status, 0) << r.err;
  const std::vector<json> lines = json_lines(r.out);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[1].at("type"), "verdict");
  EXPECT_TRUE(contains(r.err, "messages 2 (") && contains(r.err, "count reached")) << r.err;
}

TEST(telemetry_cli, DamagedFileCountsDropsAndKeepsTheGoodMessages) {
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  Bytes stream = {0x03, 0x57, 0x9B, 0x00};                    // the tail of an earlier frame: short
  append(stream, estimate_frame(enc, 1, sample_estimate()));  // good
  Bytes bad = packet_of(verdict_frame(enc, 2, sample_verdict()));
  bad[20] ^= 0x01;
  append(stream, frame_of(bad));      // crc_mismatch: seq 1 missed
  append(stream, Bytes(2000, 0x41));  // oversize
  append(stream, Bytes{0});
  append(stream, crafted_frame(3, 2, Bytes(12, 0x04), 1, 2));  // particles with dim 4: out_of_range
  append(stream, crafted_frame(200, 3, Bytes{}, 1, 2));        // unknown_type
  enc.next_seq = 10;                                           // 4 .. 9 never arrive
  append(stream, verdict_frame(enc, 3, sample_verdict()));     // good
  const Bytes last = counters_frame(enc, 4, {{1, 1}});
  append(stream, Bytes(last.begin(), last.end() - 5));  // truncated
  const cli_test::TempDir dir;
  write_bytes(dir.path() / "damaged.bin", stream);
  const CommandResult r = run_pliant("telemetry --file " + quoted(dir / "damaged.bin"));
  EXPECT_EQ(r.status, 0) << "drops are counted, not failures: " << r.err;
  const std::vector<json> lines = json_lines(r.out);
  ASSERT_EQ(lines.size(), 2u);
  EXPECT_EQ(lines[0].at("type"), "estimate");
  EXPECT_EQ(lines[1].at("type"), "verdict");
  EXPECT_EQ(lines[1].at("seq"), 10);
  ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_TRUE(contains(r.err,
                       "messages 2 (estimate 1, verdict 1, particles 0, counters 0); dropped 6 (cobs_error 0, "
                       "crc_mismatch 1, oversize 1, short_packet 1, version 0, bad_length 0, out_of_range 1, "
                       "unknown_type 1, truncated 1); sequence: 7 missed, 0 backward"))
      << r.err;
}

TEST(telemetry_cli, GarbageOnlyFile) {
  const cli_test::TempDir dir;
  Bytes garbage;
  for (int i = 0; i < 5000; ++i) garbage.push_back(static_cast<std::uint8_t>((i * 7919) % 251));
  write_bytes(dir.path() / "noise.bin", garbage);
  const CommandResult r = run_pliant("telemetry --file " + quoted(dir / "noise.bin"));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_TRUE(contains(r.err, "pliant telemetry: messages 0 (")) << r.err;
  EXPECT_FALSE(contains(r.err, "dropped 0 ")) << r.err;
}

TEST(telemetry_cli, RecordingReadBackWithTheReader) {
  const cli_test::TempDir dir;
  Bytes stream = recording_stream(4);
  // A fifth frame cut in the middle of its second chunk: dropped, never half-written.
  const Bytes fifth = [] {
    pliant_tm_encoder_t enc;
    pliant_tm_encoder_init(&enc, 12);
    Bytes b;
    for (const Bytes& chunk : particle_chunks(enc, 10'200'000, make_particle_frame(4, 2, 30), 200)) append(b, chunk);
    return b;
  }();
  append(stream, Bytes(fifth.begin(), fifth.end() - 40));
  write_bytes(dir.path() / "capture.bin", stream);
  const std::string rec = dir / "rec";
  const CommandResult r = run_pliant("telemetry --file " + quoted(dir / "capture.bin") + " --recording " + quoted(rec));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "");
  ASSERT_EQ(r.err_lines().size(), 1u) << r.err;
  EXPECT_TRUE(contains(r.err, "truncated 1)")) << r.err;
  EXPECT_TRUE(contains(r.err, "; particle frames 4 kept, 1 dropped (incomplete 1, before_rest 0, shape 0, time 0)"))
      << r.err;
  EXPECT_TRUE(contains(r.err, "; wrote " + rec)) << r.err;

  const host::Recording recording = host::read_recording(rec);
  EXPECT_EQ(recording.dimension, 2);
  EXPECT_EQ(recording.particle_count, 30);
  EXPECT_EQ(recording.length_unit, "m");
  ASSERT_EQ(recording.frame_count(), 4);
  for (int k = 0; k < 4; ++k) {
    EXPECT_DOUBLE_EQ(recording.frame_times_s[static_cast<std::size_t>(k)], 10.0 + 0.033 * k);
    const ParticleFrame f = make_particle_frame(static_cast<std::uint32_t>(k), 2, 30, k == 0);
    for (int id = 0; id < 30; ++id) {
      const auto i = static_cast<std::size_t>(id);
      ASSERT_EQ(recording.observed(k, id), f.status[i] == PLIANT_TM_OBSERVED) << k << " " << id;
      if (recording.observed(k, id)) {
        EXPECT_EQ(static_cast<float>(recording.position(k, id, 0)), f.positions[2 * i]);
        EXPECT_EQ(static_cast<float>(recording.position(k, id, 1)), f.positions[2 * i + 1]);
      }
    }
  }
  std::size_t entries = 0;
  for (const auto& entry : fs::directory_iterator(dir.path())) entries += entry.path().filename() != "capture.bin";
  EXPECT_EQ(entries, 1u) << "only the recording, no temporary directory";
}

TEST(telemetry_cli, RecordingUnitAndTrailingSlash) {
  const cli_test::TempDir dir;
  write_bytes(dir.path() / "capture.bin", recording_stream(2));
  fs::create_directories(dir.path() / "empty");
  const CommandResult r = run_pliant("telemetry --file " + quoted(dir / "capture.bin") + " --recording " +
                                     quoted(dir / "empty/") + " --length-unit px");
  EXPECT_EQ(r.status, 0) << r.err;
  const host::Recording recording = host::read_recording(dir / "empty");
  EXPECT_EQ(recording.length_unit, "px");
  EXPECT_EQ(recording.frame_count(), 2);
}

TEST(telemetry_cli, NoUsableFrameWritesNothing) {
  const cli_test::TempDir dir;
  // Estimates only; then a stream whose every frame is cut or damaged.
  pliant_tm_encoder_t enc;
  pliant_tm_encoder_init(&enc, 0);
  write_bytes(dir.path() / "estimates.bin", estimate_frame(enc, 1, sample_estimate()));
  Bytes cut = recording_stream(1);
  cut.resize(cut.size() / 2);
  write_bytes(dir.path() / "cut.bin", cut);
  for (const char* input : {"estimates.bin", "cut.bin"}) {
    const std::string rec = dir / "rec";
    const CommandResult r = run_pliant("telemetry --file " + quoted(dir / input) + " --recording " + quoted(rec));
    EXPECT_EQ(r.status, 1) << input << ": " << r.err;
    ASSERT_EQ(r.err_lines().size(), 2u) << r.err;
    EXPECT_TRUE(contains(r.err_lines()[0], "; particle frames 0 kept")) << r.err;
    EXPECT_EQ(r.err_lines()[1],
              "pliant telemetry: no complete particle frame observing every particle; nothing written to " + rec);
    EXPECT_FALSE(fs::exists(rec));
    std::size_t entries = 0;
    for (const auto& entry : fs::directory_iterator(dir.path())) entries += entry.is_directory() ? 1u : 0u;
    EXPECT_EQ(entries, 0u) << "no temporary directory left";
  }
}

TEST(telemetry_cli, RefusesANonEmptyRecordingDirectory) {
  const cli_test::TempDir dir;
  write_bytes(dir.path() / "capture.bin", recording_stream(2));
  fs::create_directories(dir.path() / "rec");
  cli_test::write_text(dir.path() / "rec" / "keep.txt", "mine");
  const CommandResult r =
      run_pliant("telemetry --file " + quoted(dir / "capture.bin") + " --recording " + quoted(dir / "rec"));
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "pliant telemetry: " + (dir / "rec") + " is not empty; give a new directory for the recording\n");
  EXPECT_EQ(read_text(dir.path() / "rec" / "keep.txt"), "mine");
}

TEST(telemetry_cli, UsageErrors) {
  const cli_test::TempDir dir;
  write_bytes(dir.path() / "c.bin", small_stream());
  const std::string file = "--file " + quoted(dir / "c.bin");
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "give one source"},
      {file + " --udp 5000", "excludes"},
      {"--serial /dev/null --file x", "excludes"},
      {file + " --baud 9600", "requires --serial"},
      {file + " --bind 0.0.0.0", "requires --udp"},
      {file + " -o x.jsonl --recording r", "excludes"},
      {file + " --length-unit px", "requires --recording"},
      {file + " --recording r --length-unit mm", "--length-unit"},
      {file + " --count 0", "--count"},
      {file + " --count -3", "--count"},
      {file + " --duration 0", "--duration must be > 0 seconds"},
      {file + " --duration -1", "--duration must be > 0 seconds"},
      {file + " --duration nan", "--duration"},
      {"--udp 0", "--udp"},
      {"--udp 70000", "--udp"},
      {"--udp 5000 --bind localhost", "'localhost' is not a numeric IPv4 or IPv6 address"},
      {"--serial /dev/null --baud 12345", "unsupported baud rate 12345"},
      {file + " -o " + quoted(dir.path().string()), "is a directory"},
  };
  for (const auto& [arguments, message] : cases) {
    const CommandResult r = run_pliant("telemetry " + arguments);
    EXPECT_EQ(r.status, 2) << arguments << "\n" << r.err;
    ASSERT_EQ(r.err_lines().size(), 1u) << arguments << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("pliant telemetry: ", 0), 0u) << r.err;
    EXPECT_TRUE(contains(r.err, message)) << arguments << "\n" << r.err;
    EXPECT_EQ(r.out, "") << arguments;
  }
}

TEST(telemetry_cli, SourceThatCannotBeOpened) {
  CommandResult r = run_pliant("telemetry --file /nonexistent/capture.bin");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "pliant telemetry: /nonexistent/capture.bin: cannot open: No such file or directory\n");
  r = run_pliant("telemetry --serial /dev/null");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "pliant telemetry: /dev/null: not a serial port (no terminal attributes)\n");
  r = run_pliant("telemetry --serial /nonexistent/ttyUSB9");
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(contains(r.err, "/nonexistent/ttyUSB9: cannot open")) << r.err;
}

// ---- live sources: the command runs in the background --------------------------------------

// `pliant telemetry ARGS` with stdout to a file and stderr to a pipe read line by line.
class Background {
 public:
  explicit Background(const std::vector<std::string>& arguments) {
    int pipe_fds[2];
    if (::pipe2(pipe_fds, O_CLOEXEC) != 0) throw std::runtime_error("pipe");
    err_ = pipe_fds[0];
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    const std::string out = out_dir_ / "stdout";
    posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, pipe_fds[1], 2);
    std::vector<std::string> args = {PLIANT_EXE, "telemetry"};
    args.insert(args.end(), arguments.begin(), arguments.end());
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    const int spawned = posix_spawn(&pid_, PLIANT_EXE, &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    ::close(pipe_fds[1]);
    if (spawned != 0) throw std::runtime_error("posix_spawn");
  }
  ~Background() {
    if (pid_ > 0) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
    ::close(err_);
  }
  Background(const Background&) = delete;
  Background& operator=(const Background&) = delete;

  /// The next stderr line, waiting at most timeout_s ("" on timeout or end).
  std::string line(double timeout_s) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (true) {
      const std::size_t end = buffer_.find('\n');
      if (end != std::string::npos) {
        std::string out = buffer_.substr(0, end);
        buffer_.erase(0, end + 1);
        return out;
      }
      const auto left =
          std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      if (left.count() <= 0) return "";
      pollfd entry{err_, POLLIN, 0};
      if (::poll(&entry, 1, static_cast<int>(left.count())) <= 0) continue;
      char chunk[256];
      const ssize_t n = ::read(err_, chunk, sizeof chunk);
      if (n <= 0) return "";
      buffer_.append(chunk, static_cast<std::size_t>(n));
    }
  }

  /// Exit status, waiting at most timeout_s (-1: still running, then killed).
  int wait(double timeout_s) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    while (std::chrono::steady_clock::now() < deadline) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        pid_ = -1;
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return -1;
  }

  void signal(int number) const { ::kill(pid_, number); }
  std::string out() const { return read_text(out_dir_ / "stdout"); }

 private:
  cli_test::TempDir out_dir_;
  pid_t pid_ = -1;
  int err_ = -1;
  std::string buffer_;
};

// A UDP port free a moment ago.
int free_udp_port() {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t size = sizeof address;
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
      ::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size) != 0) {
    throw std::runtime_error("no free UDP port");
  }
  ::close(fd);
  return ntohs(address.sin_port);
}

void send_datagrams(int port, const Bytes& stream, std::size_t size) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  for (std::size_t at = 0; at < stream.size(); at += size) {
    const std::size_t n = std::min(size, stream.size() - at);
    ::sendto(fd, stream.data() + at, n, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to);
  }
  ::close(fd);
}

TEST(telemetry_cli, UdpOnLoopback) {
  const int port = free_udp_port();
  Background run({"--udp", std::to_string(port), "--count", "5", "--duration", "20"});
  ASSERT_EQ(run.line(10), "pliant telemetry: reading udp 127.0.0.1:" + std::to_string(port) + " (Ctrl-C to stop)");
  send_datagrams(port, small_stream(), 100);
  EXPECT_EQ(run.wait(20), 0);
  const std::vector<json> lines = json_lines(run.out());
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[0].at("type"), "estimate");
  EXPECT_EQ(lines[4].at("counters").at("guard_cycles"), 1000);
  const std::string summary = run.line(5);
  EXPECT_TRUE(contains(summary, "messages 5 (estimate 1, verdict 1, particles 2, counters 1); dropped 0"));
  EXPECT_TRUE(contains(summary, "count reached")) << summary;
}

TEST(telemetry_cli, UdpDurationAndInterruptWriteTheRecording) {
  {
    const int port = free_udp_port();
    Background run({"--udp", std::to_string(port), "--duration", "0.5"});
    EXPECT_FALSE(run.line(10).empty());
    EXPECT_EQ(run.wait(10), 0);
    EXPECT_EQ(run.out(), "");
    EXPECT_TRUE(contains(run.line(5), "messages 0 ("));
  }
  const cli_test::TempDir dir;
  const std::string rec = dir / "rec";
  const int port = free_udp_port();
  Background run({"--udp", std::to_string(port), "--bind", "127.0.0.1", "--recording", rec});
  ASSERT_FALSE(run.line(10).empty());
  send_datagrams(port, recording_stream(3), 1000);
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));  // time to read the queued datagrams
  run.signal(SIGINT);                                            // Ctrl-C: the stream ends, the recording is written
  EXPECT_EQ(run.wait(10), 0);
  const std::string summary = run.line(5);
  EXPECT_TRUE(contains(summary, "stopped; particle frames 3 kept")) << summary;
  EXPECT_EQ(host::read_recording(rec).frame_count(), 3);
}

TEST(telemetry_cli, SerialPseudoTerminal) {
  const int master = ::posix_openpt(O_RDWR | O_NOCTTY | O_CLOEXEC);
  ASSERT_GE(master, 0);
  ASSERT_EQ(::grantpt(master), 0);
  ASSERT_EQ(::unlockpt(master), 0);
  const std::string slave = ::ptsname(master);
  Background run({"--serial", slave, "--baud", "57600", "--count", "5", "--duration", "20"});
  EXPECT_EQ(run.line(10), "pliant telemetry: reading " + slave + " at 57600 baud (Ctrl-C to stop)");
  const Bytes stream = small_stream();
  ASSERT_EQ(::write(master, stream.data(), stream.size()), static_cast<ssize_t>(stream.size()));
  EXPECT_EQ(run.wait(20), 0);
  ::close(master);
  const std::vector<json> lines = json_lines(run.out());
  ASSERT_EQ(lines.size(), 5u);
  EXPECT_EQ(lines[1].at("type"), "verdict");
  EXPECT_EQ(lines[2].at("positions").size(), 76u);
  EXPECT_TRUE(contains(run.line(5), "dropped 0 ("));
}

}  // namespace
}  // namespace pliant::telemetry_test
