// `pliant record` end to end: a Robotiq gripper and an FT 300 served by the Modbus emulator in
// this process (TCP on 127.0.0.1), a short Motion-JPEG video as the colour source; the recording
// must read back, share one clock across its files and replay. Also the refusals: malformed
// specs, an unreachable device, an existing output.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "cli_test_support.hpp"
#include "pliant/drivers/modbus/emulator/modbus_emulator.hpp"
#include "pliant/host/recording.hpp"
#ifdef PLIANT_RECORD_ONI
#include <opencv2/imgcodecs.hpp>

#include "pliant/drivers/openni2/openni2_camera.hpp"
#include "pliant/hal/clock.hpp"
#endif

namespace pliant::cli_test {
namespace {

namespace modbus = drivers::modbus;

// Rows of a CSV file (header first), split at commas.
std::vector<std::vector<std::string>> csv_rows(const fs::path& path) {
  std::vector<std::vector<std::string>> rows;
  for (const std::string& line : lines_of(read_text(path))) {
    std::vector<std::string> fields;
    std::size_t start = 0;
    for (;;) {
      const std::size_t comma = line.find(',', start);
      fields.push_back(line.substr(start, comma - start));
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    rows.push_back(fields);
  }
  return rows;
}

// A blurred random texture, squeezed towards row 100 a little more in every frame (an object
// pressed from above), written as Motion-JPEG at `fps`.
void write_video(const std::string& path, int frames, double fps) {
  cv::Mat texture(120, 160, CV_8UC3);
  cv::RNG rng(7);
  rng.fill(texture, cv::RNG::UNIFORM, 0, 255);
  cv::GaussianBlur(texture, texture, cv::Size(0, 0), 2.0);
  cv::VideoWriter writer(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps, texture.size(), true);
  ASSERT_TRUE(writer.isOpened());
  for (int k = 0; k < frames; ++k) {
    const double s = 1.0 - 0.01 * k;
    const cv::Mat squeeze = (cv::Mat_<double>(2, 3) << 1, 0, 0, 0, s, 100 * (1 - s));
    cv::Mat frame;
    cv::warpAffine(texture, frame, squeeze, texture.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT);
    writer.write(frame);
  }
}

// A TCP port on 127.0.0.1 where nobody listens (bound, then closed).
int closed_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  EXPECT_GE(fd, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = 0;
  EXPECT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  socklen_t length = sizeof address;
  EXPECT_EQ(::getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length), 0);
  ::close(fd);
  return ntohs(address.sin_port);
}

// Entries of `directory` whose name starts with `prefix` (finds left-over partial recordings).
std::vector<std::string> entries_starting(const fs::path& directory, const std::string& prefix) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(directory)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) == 0) names.push_back(name);
  }
  return names;
}

class CliRecordTest : public ::testing::Test {
 protected:
  void SetUp() override {
    modbus::ModbusEmulatorConfig config;
    config.real_time = true;
    emulator_ = std::make_unique<modbus::ModbusEmulator>(config);
    std::string error;
    ASSERT_TRUE(emulator_->start(&error)) << error;
    port_ = emulator_->port();
    const double wrench[6] = {1.5, -2.0, 12.25, 0.1, -0.2, 0.05};
    emulator_->set_wrench(wrench);
    emulator_->set_gripper_width(0.080);
  }
  void TearDown() override {
    stop_motion();
    emulator_->stop();
  }

  // Once `clients` drivers are connected (the recorder has opened its devices), closes the
  // simulated jaws from 80 mm by 1 mm every 25 ms (down to 40 mm) until stopped.
  void start_motion(std::uint64_t clients) {
    moving_ = true;
    motion_ = std::thread([this, clients] {
      while (moving_ && emulator_->counters().connections < clients) {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
      double width = 0.080;
      while (moving_) {
        std::this_thread::sleep_for(std::chrono::milliseconds(25));
        width = std::max(0.040, width - 0.001);
        emulator_->set_gripper_width(width);
      }
    });
  }
  void stop_motion() {
    moving_ = false;
    if (motion_.joinable()) motion_.join();
  }

  std::string modbus(const std::string& kind) const { return kind + ":127.0.0.1:" + std::to_string(port_); }

  std::unique_ptr<modbus::ModbusEmulator> emulator_;
  int port_ = 0;
  std::atomic<bool> moving_{false};
  std::thread motion_;
};

TEST_F(CliRecordTest, GripperForceAndVideoOnOneClock) {
  TempDir dir;
  const std::string video = dir / "in.avi";
  write_video(video, 40, 20.0);  // 2 s: the duration ends the recording first
  const std::string rec = dir / "rec";
  start_motion(2);
  const CommandResult r = run_pliant("record --gripper " + modbus("robotiq-tcp") + " --ft " + modbus("ft300-tcp") +
                                     " --color " + quoted("video:" + video) + " --duration 1.5 -q -o " + quoted(rec));
  stop_motion();
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("wrote " + rec), std::string::npos) << r.out;
  EXPECT_TRUE(entries_starting(dir.path(), "rec.").empty());  // no partial directory left

  // The recording reads back: the jaws as particles, the wrench on the driven jaw.
  const host::Recording recording = host::read_recording(rec);
  EXPECT_EQ(recording.dimension, 2);
  EXPECT_EQ(recording.length_unit, "m");
  ASSERT_EQ(recording.particle_count, 2);
  EXPECT_EQ(recording.fixed, std::vector<int>{0});
  ASSERT_EQ(recording.driven.size(), 1u);
  EXPECT_EQ(recording.driven[0].id, 1);
  EXPECT_EQ(recording.wrench_applied_to, std::vector<int>{1});
  EXPECT_EQ(recording.files.at("color_video"), "color.avi");
  EXPECT_EQ(recording.files.at("color_frames"), "color_frames.csv");
  EXPECT_EQ(recording.files.at("gripper_state"), "gripper_state.csv");
  EXPECT_EQ(recording.files.count("gripper"), 0u);  // a Robotiq senses no grip force: no gripper.csv
  EXPECT_FALSE(fs::exists(fs::path(rec) / "gripper.csv"));
  EXPECT_EQ(recording.meta["record"]["stop"], "duration");
  EXPECT_EQ(recording.meta["devices"]["gripper"]["spec"], modbus("robotiq-tcp"));
  EXPECT_EQ(recording.meta["devices"]["ft"]["driver"], "modbus");
  EXPECT_TRUE(recording.meta["devices"]["color"]["counters"].contains("dropped"));
  EXPECT_TRUE(recording.meta["devices"]["gripper"]["counters"].contains("faults"));
  const double recorded_s = recording.meta["record"]["recorded_s"].get<double>();
  EXPECT_GE(recorded_s, 1.5);
  EXPECT_LT(recorded_s, 10.0);

  // Plausible counts: the gripper is polled at most every 10 ms, the sensor every 5 ms, the
  // video plays at 20 Hz; a loaded machine gives fewer, never more.
  const int frames = recording.frame_count();
  EXPECT_GE(frames, 5);
  EXPECT_LE(frames, 1 + static_cast<int>(recorded_s / 0.01) + 1);
  EXPECT_GE(recording.wrench.size(), 5u);
  EXPECT_LE(recording.wrench.size(), 2 + static_cast<std::size_t>(recorded_s / 0.005));
  // Jaw A stays at the origin; jaw B follows the closing fingers.
  std::set<double> widths;
  for (int f = 0; f < frames; ++f) {
    EXPECT_EQ(recording.position(f, 0, 0), 0.0);
    EXPECT_EQ(recording.position(f, 1, 1), 0.0);
    const double w = recording.position(f, 1, 0);
    EXPECT_GE(w, 0.039);
    EXPECT_LE(w, 0.081);
    widths.insert(w);
  }
  EXPECT_GE(widths.size(), 2u) << "the jaws did not move in the recording";
  EXPECT_LT(recording.position(frames - 1, 1, 0), recording.position(0, 1, 0));
  for (const host::WrenchSample& w : recording.wrench) {
    EXPECT_DOUBLE_EQ(w.force_n[0], 1.5);
    EXPECT_DOUBLE_EQ(w.force_n[2], 12.25);
    EXPECT_DOUBLE_EQ(w.torque_nm[1], -0.2);
  }

  // One clock: every stamp lies within the recording (t = 0 is taken before the devices start).
  const double slack = 0.05;
  for (double t : recording.frame_times_s) {
    EXPECT_GE(t, 0.0);
    EXPECT_LE(t, recorded_s + slack);
  }
  for (const host::WrenchSample& w : recording.wrench) {
    EXPECT_GE(w.t_s, 0.0);
    EXPECT_LE(w.t_s, recorded_s + slack);
  }
  const auto gripper_state = csv_rows(fs::path(rec) / "gripper_state.csv");
  ASSERT_EQ(gripper_state.size(), static_cast<std::size_t>(frames) + 1);
  EXPECT_EQ(gripper_state[0],
            (std::vector<std::string>{"t", "width_m", "target_width_m", "force_n", "current_a", "status_bits"}));
  EXPECT_EQ(gripper_state[1][3], "nan");  // force not sensed
  EXPECT_DOUBLE_EQ(std::stod(gripper_state[1][0]), recording.frame_times_s[0]);
  // Colour frames: a file plays in real time from the start, so frame k is due k/20 s after the
  // first, on the same clock.
  const auto color_frames = csv_rows(fs::path(rec) / "color_frames.csv");
  ASSERT_GE(color_frames.size(), 6u);
  EXPECT_LE(color_frames.size(), 1u + 31u);
  EXPECT_EQ(color_frames[0], (std::vector<std::string>{"index", "t"}));
  const double t_first = std::stod(color_frames[1][1]);
  EXPECT_GE(t_first, 0.0);
  EXPECT_LE(t_first, 1.0);
  double previous = -1;
  for (std::size_t i = 1; i < color_frames.size(); ++i) {
    EXPECT_EQ(color_frames[i][0], std::to_string(i - 1));
    const double t = std::stod(color_frames[i][1]);
    EXPECT_GT(t, previous);
    EXPECT_LE(t, recorded_s + slack);
    const double periods = (t - t_first) * 20.0;
    EXPECT_NEAR(periods, std::round(periods), 1e-6) << "frame " << i - 1 << " at " << t;
    previous = t;
  }
  // The video holds as many frames as color_frames.csv names.
  cv::VideoCapture capture((fs::path(rec) / "color.avi").string());
  ASSERT_TRUE(capture.isOpened());
  int decoded = 0;
  for (cv::Mat image; capture.read(image);) {
    EXPECT_EQ(image.cols, 160);
    EXPECT_EQ(image.rows, 120);
    ++decoded;
  }
  EXPECT_EQ(static_cast<std::size_t>(decoded), color_frames.size() - 1);

  // It replays.
  const CommandResult replay = run_pliant("replay --stepped " + quoted(rec) + " -o " + quoted(dir / "replay.jsonl"));
  EXPECT_EQ(replay.status, 0) << replay.err;
  EXPECT_FALSE(read_text(dir / "replay.jsonl").empty());
}

TEST_F(CliRecordTest, EndsWhenTheFileSourceEndsAndForceReplaces) {
  TempDir dir;
  const std::string video = dir / "short.avi";
  write_video(video, 8, 20.0);  // 0.4 s, no --duration
  const std::string rec = dir / "rec";
  const std::string args =
      "record --gripper " + modbus("robotiq-tcp") + " --color " + quoted("video:" + video) + " -q -o " + quoted(rec);
  CommandResult r = run_pliant(args);
  ASSERT_EQ(r.status, 0) << r.err;
  host::Recording recording = host::read_recording(rec);
  EXPECT_EQ(recording.meta["record"]["stop"], "sources_ended");
  EXPECT_EQ(csv_rows(fs::path(rec) / "color_frames.csv").size(), 1u + 8u);  // every frame of the file
  EXPECT_EQ(recording.files.count("wrench"), 0u);

  // An existing output is refused without --force and left as it was.
  const std::string before = read_text(fs::path(rec) / "particles.csv");
  r = run_pliant(args);
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("exists; give --force"), std::string::npos) << r.err;
  EXPECT_EQ(read_text(fs::path(rec) / "particles.csv"), before);
  EXPECT_TRUE(entries_starting(dir.path(), "rec.").empty());

  // With --force a recording is replaced.
  r = run_pliant(args + " --force");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NO_THROW(host::read_recording(rec));
  EXPECT_TRUE(entries_starting(dir.path(), "rec.").empty());  // neither the partial nor the old one

  // ... but never a directory that is not a recording.
  const std::string other = dir / "other";
  fs::create_directories(other);
  write_text(fs::path(other) / "keep.txt", "mine");
  r = run_pliant("record --gripper " + modbus("robotiq-tcp") + " --duration 0.2 -q --force -o " + quoted(other));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("not a recording"), std::string::npos) << r.err;
  EXPECT_EQ(read_text(fs::path(other) / "keep.txt"), "mine");
}

TEST_F(CliRecordTest, FileNameInAnotherEncoding) {
  TempDir dir;
  const std::string video = dir / "caf\xe9.avi";  // Latin-1: not valid UTF-8
  write_video(video, 4, 20.0);
  const std::string rec = dir / "rec";
  const CommandResult r = run_pliant("record --gripper " + modbus("robotiq-tcp") + " --color " +
                                     quoted("video:" + video) + " -q -o " + quoted(rec));
  ASSERT_EQ(r.status, 0) << r.err;
  const host::Recording recording = host::read_recording(rec);
  const std::string spec = recording.meta["devices"]["color"]["spec"].get<std::string>();
  EXPECT_NE(spec.find("caf?.avi"), std::string::npos) << spec;  // recording.json stays UTF-8
}

TEST_F(CliRecordTest, MalformedSpecsWriteNothing) {
  TempDir dir;
  const std::string rec = dir / "rec";
  const std::vector<std::string> bad = {
      "--gripper robotiq-tcp:localhost:502",          // no name lookup
      "--gripper " + modbus("robotiq-tcp") + "@300",  // slave out of range
      "--ft ati-can:can0 --gripper " + modbus("robotiq-tcp"),
      "--color webcam:0 --roi 0,0,10,10",
      "--depth openni2:any --gripper robotiq-rtu:",
      "--gripper " + modbus("ft300-tcp"),                       // a --ft kind
      "--ft " + modbus("ft300-tcp"),                            // no source of particles
      "--color video:x.avi",                                    // no source of particles either
      "--gripper " + modbus("robotiq-tcp") + " --grid 3x3",     // tracking option without a region
      "--gripper " + modbus("robotiq-tcp") + " --roi 1,2,3,4",  // a region without a colour source
      "--color video:x.avi --roi 1,2,3",
      "--color video:x.avi --roi 0,0,50,50 --flow lucas",
      "--gripper " + modbus("robotiq-tcp") + " --duration -1",
      "--gripper " + modbus("robotiq-tcp") + " --gripper-stroke 5",
      "",
  };
  for (const std::string& options : bad) {
    const CommandResult r = run_pliant("record " + options + " -o " + quoted(rec));
    EXPECT_EQ(r.status, 2) << options << "\n" << r.err;
    EXPECT_EQ(r.err_lines().size(), 1u) << options << "\n" << r.err;
    EXPECT_EQ(r.err.rfind("pliant record: ", 0), 0u) << r.err;
    EXPECT_TRUE(fs::is_empty(dir.path())) << options;
  }
  EXPECT_EQ(emulator_->counters().connections, 0u);  // refused before any device was opened
}

TEST_F(CliRecordTest, UnreachableDeviceFailsAndLeavesNothing) {
  TempDir dir;
  const std::string rec = dir / "rec";
  const int port = closed_port();
  CommandResult r = run_pliant("record --gripper robotiq-tcp:127.0.0.1:" + std::to_string(port) + " --ft " +
                               modbus("ft300-tcp") + " --duration 5 -q -o " + quoted(rec));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("--gripper 'robotiq-tcp:127.0.0.1:" + std::to_string(port) + "': cannot open"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("Connection refused"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::is_empty(dir.path()));

  // A file that cannot be decoded: the colour source fails at open, after the gripper opened.
  write_text(dir / "junk.avi", "not a video");
  r = run_pliant("record --gripper " + modbus("robotiq-tcp") + " --color " + quoted("video:" + (dir / "junk.avi")) +
                 " -q -o " + quoted(rec));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("--color 'video:"), std::string::npos) << r.err;
  EXPECT_EQ(entries_starting(dir.path(), "rec"), std::vector<std::string>{});
}

#ifdef PLIANT_RECORD_ONI
// Every frame of the .oni recording as the driver decodes it, stepped (none skipped).
std::vector<cv::Mat> oni_frames(const std::string& path) {
  hal::ManualClock clock;
  drivers::openni2::Openni2CameraConfig config;
  config.source = drivers::openni2::Openni2Source::recording;
  config.location = path;
  config.playback = drivers::openni2::Openni2Playback::stepped;
  drivers::openni2::Openni2Camera camera(clock, config);
  std::vector<cv::Mat> frames;
  if (camera.configure() != hal::HalStatus::ok || camera.start() != hal::HalStatus::ok) {
    ADD_FAILURE() << camera.last_error();
    return frames;
  }
  hal::DepthFrame frame;
  while (camera.read(frame) == hal::HalStatus::ok) {
    const cv::Mat view(frame.height, frame.width, CV_16UC1, const_cast<std::uint16_t*>(frame.data),
                       static_cast<std::size_t>(frame.stride_bytes));
    frames.push_back(view.clone());
    (void)clock.advance(1.0 / 30);
  }
  return frames;
}

TEST_F(CliRecordTest, DepthFramesAsPngs) {
  TempDir dir;
  const std::string rec = dir / "rec";
  const CommandResult r = run_pliant("record --depth " + quoted(std::string("oni:") + PLIANT_RECORD_ONI) +
                                     " --gripper " + modbus("robotiq-tcp") + " --duration 20 -q -o " + quoted(rec));
  ASSERT_EQ(r.status, 0) << r.err;
  const host::Recording recording = host::read_recording(rec);
  EXPECT_EQ(recording.meta["record"]["stop"], "sources_ended");  // the 12-frame file, long before 20 s
  EXPECT_EQ(recording.files.at("depth_frames"), "depth_frames.csv");
  const auto rows = csv_rows(fs::path(rec) / "depth_frames.csv");
  EXPECT_EQ(rows[0], (std::vector<std::string>{"index", "t", "file", "depth_scale_m", "fx", "fy", "cx", "cy"}));
  ASSERT_GE(rows.size(), 3u);
  EXPECT_LE(rows.size(), 13u);
  // Each PNG is one of the file's frames, bit for bit, in order; times increase on the clock.
  const std::vector<cv::Mat> expected = oni_frames(PLIANT_RECORD_ONI);
  ASSERT_EQ(expected.size(), 12u);
  std::size_t next = 0;
  double previous = -1;
  for (std::size_t i = 1; i < rows.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "depth/%06zu.png", i - 1);
    EXPECT_EQ(rows[i][0], std::to_string(i - 1));
    EXPECT_EQ(rows[i][2], name);
    EXPECT_EQ(std::stod(rows[i][3]), 0.001);
    EXPECT_GT(std::stod(rows[i][4]), 100.0);  // fx from the stream's field of view
    const double t = std::stod(rows[i][1]);
    EXPECT_GT(t, previous);
    EXPECT_GE(t, 0.0);
    previous = t;
    const cv::Mat png = cv::imread((fs::path(rec) / rows[i][2]).string(), cv::IMREAD_UNCHANGED);
    ASSERT_EQ(png.type(), CV_16UC1);
    ASSERT_EQ(png.size(), cv::Size(640, 480));
    while (next < expected.size() && cv::norm(png, expected[next], cv::NORM_INF) != 0) ++next;
    ASSERT_LT(next, expected.size()) << rows[i][2] << " is none of the remaining frames of the file";
    ++next;
  }
}
#endif

#if PLIANT_RECORD_TRACKING
TEST_F(CliRecordTest, ParticlesTrackedInTheRecordedVideo) {
  TempDir dir;
  const std::string video = dir / "press.avi";
  write_video(video, 12, 20.0);
  const std::string rec = dir / "rec";
  const CommandResult r = run_pliant("record --color " + quoted("video:" + video) + " --ft " + modbus("ft300-tcp") +
                                     " --roi 40,20,80,70 --grid 3x4 --support bottom --driven 1 -q -o " + quoted(rec));
  ASSERT_EQ(r.status, 0) << r.err;
  const host::Recording recording = host::read_recording(rec);
  EXPECT_EQ(recording.length_unit, "px");
  EXPECT_EQ(recording.particle_count, 12);
  ASSERT_EQ(recording.driven.size(), 1u);
  EXPECT_EQ(recording.driven[0].id, 1);
  EXPECT_EQ(recording.fixed, (std::vector<int>{8, 9, 10, 11}));
  EXPECT_EQ(recording.wrench_applied_to, std::vector<int>{1});
  EXPECT_EQ(recording.files.at("track"), "track.csv");
  EXPECT_TRUE(fs::exists(fs::path(rec) / "track.csv"));
  // Every video frame tracked, at the time color_frames.csv gives it.
  const auto color_frames = csv_rows(fs::path(rec) / "color_frames.csv");
  ASSERT_EQ(static_cast<std::size_t>(recording.frame_count()), color_frames.size() - 1);
  for (int f = 0; f < recording.frame_count(); ++f) {
    EXPECT_DOUBLE_EQ(recording.frame_times_s[static_cast<std::size_t>(f)],
                     std::stod(color_frames[static_cast<std::size_t>(f) + 1][1]));
  }
  // The driven particle (top row) moves down with the squeeze; the support stays.
  const int last = recording.frame_count() - 1;
  const double driven_motion = recording.position(last, 1, 1) - recording.position(0, 1, 1);
  const double support_motion = recording.position(last, 9, 1) - recording.position(0, 9, 1);
  EXPECT_GT(driven_motion, 4.0);                           // about 7.5 px
  EXPECT_LT(std::abs(support_motion), driven_motion / 2);  // about 2.4 px
  // A region outside the frames is refused at the first frame, and nothing is kept.
  const std::string rec2 = dir / "rec2";
  const CommandResult outside = run_pliant("record --color " + quoted("video:" + video) +
                                           " --roi 150,100,80,70 --support bottom --driven 1 -q -o " + quoted(rec2));
  EXPECT_EQ(outside.status, 2) << outside.err;
  EXPECT_NE(outside.err.find("first colour frame 160x120"), std::string::npos) << outside.err;
  EXPECT_EQ(entries_starting(dir.path(), "rec2"), std::vector<std::string>{});
}
#endif

}  // namespace
}  // namespace pliant::cli_test
