// drivers/openni2 Openni2Camera on .oni recordings: the room.oni fixture (12 real Kinect depth
// frames) stepped and in real time, end of stream, stamps, restarts, lifecycle faults, stalls
// timed on the injected clock, and truncated, corrupted and missing files.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "oni_test_support.hpp"
#include "pliant/drivers/openni2/openni2_camera.hpp"
#include "pliant/hal/mock/fault_script.hpp"
#include "pliant/hal/mock/faulty_cameras.hpp"
#include "pliant/hal/clock.hpp"
#include "support/temp_dir.hpp"

namespace {

using namespace pliant::drivers::openni2;
using pliant::hal::DepthFrame;
using pliant::hal::HalStatus;
using pliant::hal::LifecycleState;
namespace oni = pliant::test_support::oni;

Openni2CameraConfig recording_config(const std::string& path, Openni2Playback playback = Openni2Playback::stepped) {
  Openni2CameraConfig config;
  config.source = Openni2Source::recording;
  config.location = path;
  config.playback = playback;
  return config;
}

// A copy of room.oni whose last depth frame OpenNI2 cannot decode (payload all 0xFF): the player
// skips it without reporting the end of the file, so a stepped read after frame 11 stalls.
std::string write_undecodable_last_frame(const pliant::test_support::TempDir& dir) {
  OniFileInfo info;
  const OniCheckResult check = check_oni_file(oni::fixture_path(), info);
  const OniNodeInfo* depth = check.ok() ? info.first_node_of_type(kOniNodeDepth) : nullptr;
  if (depth == nullptr) throw std::runtime_error("fixture check failed");
  const std::uint32_t depth_node = depth->id;
  std::vector<std::uint8_t> bytes = oni::read_bytes(oni::fixture_path());
  const oni::Record* last = nullptr;
  const std::vector<oni::Record> records = oni::records(bytes);
  for (const oni::Record& r : records) {
    if (r.type == 0x0A && r.node == depth_node) last = &r;
  }
  if (last == nullptr) throw std::runtime_error("no depth frame in the fixture");
  const auto payload = bytes.begin() + static_cast<std::ptrdiff_t>(last->offset + last->fields);
  std::fill(payload, payload + static_cast<std::ptrdiff_t>(last->payload), std::uint8_t{0xFF});
  const std::string path = dir / "last_frame_undecodable.oni";
  oni::write_bytes(path, bytes);
  return path;
}

double median_depth_m(const DepthFrame& frame, double* valid_fraction) {
  std::vector<std::uint16_t> valid;
  const std::size_t pixels = static_cast<std::size_t>(frame.width) * static_cast<std::size_t>(frame.height);
  for (std::size_t i = 0; i < pixels; ++i) {
    if (frame.data[i] != 0) valid.push_back(frame.data[i]);
  }
  *valid_fraction = static_cast<double>(valid.size()) / static_cast<double>(pixels);
  if (valid.empty()) return 0;
  std::nth_element(valid.begin(), valid.begin() + static_cast<std::ptrdiff_t>(valid.size() / 2), valid.end());
  return valid[valid.size() / 2] * frame.depth_scale_m;
}

TEST(Openni2Recording, StepsThroughAllTwelveFrames) {
  pliant::hal::ManualClock clock(100);
  Openni2Camera camera(clock, recording_config(oni::fixture_path()));
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  EXPECT_TRUE(camera.last_error().empty());
  EXPECT_EQ(camera.width(), 640);
  EXPECT_EQ(camera.height(), 480);
  EXPECT_EQ(camera.recording_info().records, 151u);
  ASSERT_EQ(camera.start(), HalStatus::ok);

  std::vector<std::uint64_t> ts;
  double previous_stamp = -1;
  for (int k = 1; k <= 12; ++k) {
    DepthFrame frame;
    ASSERT_EQ(camera.read(frame), HalStatus::ok) << "frame " << k;
    EXPECT_EQ(frame.width, 640);
    EXPECT_EQ(frame.height, 480);
    EXPECT_EQ(frame.stride_bytes, 1280);
    EXPECT_DOUBLE_EQ(frame.depth_scale_m, 1e-3);
    EXPECT_EQ(frame.header.sequence, static_cast<std::uint64_t>(k));
    EXPECT_EQ(frame.header.status_bits, 0u);
    EXPECT_GT(frame.header.stamp_s, previous_stamp);
    previous_stamp = frame.header.stamp_s;
    const Openni2CameraStats stats = camera.stats();
    EXPECT_EQ(stats.last_frame_index, k);
    ts.push_back(stats.last_timestamp_us);
    // A room: most pixels measured, the median a few metres away.
    double valid = 0;
    const double median = median_depth_m(frame, &valid);
    EXPECT_GT(valid, 0.5) << "frame " << k;
    EXPECT_GT(median, 0.8) << "frame " << k;
    EXPECT_LT(median, 5.0) << "frame " << k;
    // Stepped stamps: the clock at start plus the file's time since the first frame.
    EXPECT_NEAR(frame.header.stamp_s, 100 + static_cast<double>(ts.back() - ts.front()) * 1e-6, 1e-9);
    if (k == 12) {
      EXPECT_TRUE(camera.end_of_stream()) << "known at the last frame";
    } else {
      EXPECT_FALSE(camera.end_of_stream());
    }
  }
  for (std::size_t i = 1; i < ts.size(); ++i) {
    EXPECT_GT(ts[i], ts[i - 1]);
    EXPECT_NEAR(static_cast<double>(ts[i] - ts[i - 1]), 33370, 200) << "30 fps";
  }
  EXPECT_EQ(ts.front(), 11680u);
  EXPECT_EQ(ts.back(), 378742u);

  DepthFrame after;
  EXPECT_EQ(camera.read(after), HalStatus::no_data);
  EXPECT_EQ(camera.read(after), HalStatus::no_data);
  const Openni2CameraStats stats = camera.stats();
  EXPECT_TRUE(stats.end_of_stream);
  EXPECT_FALSE(stats.ended_early);
  EXPECT_EQ(stats.received, 12u);
  EXPECT_EQ(stats.rejected, 0u);
  EXPECT_EQ(camera.counters().samples, 12u);
  EXPECT_EQ(camera.counters().dropped, 0u);
  EXPECT_EQ(camera.counters().no_data, 2u);
  EXPECT_EQ(camera.stop(), HalStatus::ok);
  EXPECT_EQ(camera.cleanup(), HalStatus::ok);
}

// The .oni played through hal's FaultyDepthCamera with a fault script: the media replay with
// scripted faults that hardware-in-the-loop tests use. Stepped stamps start at 100 s and advance
// 33.4 ms per frame (frame k at ~100 + 0.0334 (k - 1)): frame 2 dropped, frame 4 all zero,
// frame 6 frozen on frame 5's pixels; the read made while the clock is at 200 is disconnected.
TEST(Openni2Recording, PlaysThroughScriptedFaults) {
  pliant::hal::ManualClock clock(100);
  Openni2Camera player(clock, recording_config(oni::fixture_path()));
  pliant::hal::FaultyDepthCamera camera(player, clock, 640 * 480 * 2);
  const std::string text =
      "100.02 drop depth 0.03\n"
      "100.09 nan depth 0.02\n"
      "100.155 freeze_data depth 0.02\n"
      "200 disconnect depth 1\n";
  pliant::hal::FaultScript script;
  pliant::hal::FaultScriptError error;
  ASSERT_EQ(pliant::hal::parse_fault_script(text.data(), text.size(), script, error), HalStatus::ok) << error.message;
  ASSERT_EQ(camera.set_fault_schedule(script.of(pliant::hal::FaultDevice::depth_camera)), HalStatus::ok);
  ASSERT_EQ(camera.configure(), HalStatus::ok) << player.last_error();
  ASSERT_EQ(camera.start(), HalStatus::ok);
  std::vector<std::uint16_t> fifth;
  int delivered = 0, zero_frames = 0;
  for (int k = 1; k <= 12; ++k) {
    DepthFrame frame;
    const HalStatus status = camera.read(frame);
    if (k == 2) {
      EXPECT_EQ(status, HalStatus::no_data);
      continue;
    }
    ASSERT_EQ(status, HalStatus::ok) << "frame " << k;
    ++delivered;
    EXPECT_EQ(frame.header.sequence, static_cast<std::uint64_t>(k));
    const std::vector<std::uint16_t> pixels(frame.data, frame.data + 640 * 480);
    double valid = 0;
    median_depth_m(frame, &valid);
    if (k == 4) {
      EXPECT_EQ(valid, 0.0);
      ++zero_frames;
    } else {
      EXPECT_GT(valid, 0.5) << "frame " << k;
    }
    if (k == 5) fifth = pixels;
    if (k == 6) {
      EXPECT_EQ(pixels, fifth) << "frozen on frame 5";
    }
  }
  EXPECT_EQ(delivered, 11);
  EXPECT_EQ(zero_frames, 1);
  ASSERT_EQ(clock.set(200.5), HalStatus::ok);
  DepthFrame frame;
  EXPECT_EQ(camera.read(frame), HalStatus::disconnected);
  EXPECT_EQ(camera.counters().dropped, 1u);
  EXPECT_EQ(camera.counters().disconnected, 1u);
  EXPECT_EQ(camera.fault_counters().of(pliant::hal::FaultKind::drop), 1u);
  EXPECT_EQ(camera.fault_counters().of(pliant::hal::FaultKind::nan), 1u);
  EXPECT_EQ(camera.fault_counters().of(pliant::hal::FaultKind::freeze_data), 1u);
  EXPECT_EQ(player.counters().samples, 12u);  // the player delivered every frame
  EXPECT_EQ(camera.stop(), HalStatus::ok);
  EXPECT_EQ(camera.cleanup(), HalStatus::ok);
}

TEST(Openni2Recording, IntrinsicsFromTheRecordedFieldOfView) {
  pliant::hal::ManualClock clock;
  Openni2CameraConfig config = recording_config(oni::fixture_path());
  config.fallback_intrinsics = DepthIntrinsics{500, 500, 320, 240, 640, 480};  // not used: the FOV is valid
  Openni2Camera camera(clock, config);
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  const Openni2CameraStats stats = camera.stats();
  EXPECT_EQ(stats.intrinsics_source, IntrinsicsSource::device_fov);
  EXPECT_STREQ(intrinsics_source_name(stats.intrinsics_source), "device_fov");
  // PrimeSense depth: about 58 x 45 degrees.
  EXPECT_NEAR(stats.hfov_rad * 180 / 3.14159265358979, 58.1, 0.5);
  EXPECT_NEAR(stats.vfov_rad * 180 / 3.14159265358979, 45.3, 0.5);
  const DepthIntrinsics k = camera.intrinsics();
  EXPECT_NEAR(k.fx, 576, 3);
  EXPECT_NEAR(k.fy, 576, 3);
  EXPECT_NEAR(k.fx / k.fy, 1, 0.01) << "square pixels";
  EXPECT_DOUBLE_EQ(k.cx, 319.5);
  EXPECT_DOUBLE_EQ(k.cy, 239.5);

  ASSERT_EQ(camera.start(), HalStatus::ok);
  DepthFrame frame;
  ASSERT_EQ(camera.read(frame), HalStatus::ok);
  EXPECT_DOUBLE_EQ(frame.fx, k.fx);
  EXPECT_DOUBLE_EQ(frame.cy, k.cy);
  // The cloud of the room spans a plausible volume: metres wide, in front of the camera.
  std::vector<double> xyz(640 * 480 * 3);
  const PointsResult points = depth_to_points(frame, xyz.data(), 640 * 480);
  ASSERT_EQ(points.status, PointsStatus::ok);
  double min_x = 1e9, max_x = -1e9, min_z = 1e9;
  for (std::size_t i = 0; i < 640u * 480u; ++i) {
    if (std::isnan(xyz[3 * i])) continue;
    min_x = std::min(min_x, xyz[3 * i]);
    max_x = std::max(max_x, xyz[3 * i]);
    min_z = std::min(min_z, xyz[3 * i + 2]);
  }
  EXPECT_GT(points.valid_points, 640u * 480u / 2);
  EXPECT_GT(max_x - min_x, 1.0);
  EXPECT_LT(max_x - min_x, 12.0);
  EXPECT_GT(min_z, 0.3);
}

TEST(Openni2Recording, RealTimePlaybackReachesTheEnd) {
  pliant::hal::SteadyClock clock;
  Openni2CameraConfig config = recording_config(oni::fixture_path(), Openni2Playback::real_time);
  config.playback_speed = 2;
  Openni2Camera camera(clock, config);
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  ASSERT_EQ(camera.start(), HalStatus::ok);
  std::vector<std::uint64_t> sequences;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
  while (!camera.end_of_stream() && std::chrono::steady_clock::now() < give_up) {
    DepthFrame frame;
    const double before = clock.now_s();
    const HalStatus status = camera.read(frame);
    if (status == HalStatus::ok) {
      sequences.push_back(frame.header.sequence);
      EXPECT_LE(frame.header.stamp_s, clock.now_s()) << "never stamped after its read";
      EXPECT_GT(frame.header.stamp_s, before - 5);
    } else {
      ASSERT_EQ(status, HalStatus::no_data);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
  }
  ASSERT_TRUE(camera.end_of_stream()) << "playback did not end within 30 s";
  ASSERT_FALSE(sequences.empty());
  EXPECT_TRUE(std::is_sorted(sequences.begin(), sequences.end()));
  EXPECT_EQ(std::adjacent_find(sequences.begin(), sequences.end()), sequences.end()) << "no frame twice";
  EXPECT_EQ(sequences.back(), 12u) << "the newest frame is never lost";
  EXPECT_FALSE(camera.stats().ended_early);
  // Frames passed over (if the loop was slow) are the HAL's dropped count.
  EXPECT_EQ(camera.counters().dropped, 12u - sequences.size());
  EXPECT_EQ(camera.stop(), HalStatus::ok);
  EXPECT_EQ(camera.cleanup(), HalStatus::ok);
}

// A stepped read blocks at most step_timeout_s of real time; whether a read that found nothing
// ends the stream is the injected clock's decision. The fixture with an undecodable last frame:
// OpenNI2's player skips it, then reports the end of the file while the read waits, so only the
// first read after frame 11 is a stall (the next one sees the end of the file).
class Openni2SteppedStall : public ::testing::Test {
 protected:
  // Plays frames 1..11, moving `clock` between reads by more than step_timeout_s (time between
  // reads is no stall), then makes the stalled read; true when that read ended the stream.
  bool stalled_read_ends_stream(const pliant::hal::Clock& clock, const std::function<void()>& between_reads) {
    Openni2CameraConfig config = recording_config(path_);
    config.step_timeout_s = 0.2;
    camera_ = std::make_unique<Openni2Camera>(clock, config);
    EXPECT_EQ(camera_->configure(), HalStatus::ok) << camera_->last_error();
    EXPECT_EQ(camera_->start(), HalStatus::ok);
    DepthFrame frame;
    for (int k = 1; k <= 11; ++k) {
      EXPECT_EQ(camera_->read(frame), HalStatus::ok) << "frame " << k;
      between_reads();
    }
    const auto began = std::chrono::steady_clock::now();
    EXPECT_EQ(camera_->read(frame), HalStatus::no_data);
    real_wait_ = std::chrono::steady_clock::now() - began;
    return camera_->end_of_stream();
  }

  pliant::test_support::TempDir dir_{"pliant_oni_"};
  std::string path_ = write_undecodable_last_frame(dir_);
  std::unique_ptr<Openni2Camera> camera_;
  std::chrono::steady_clock::duration real_wait_{};
};

TEST_F(Openni2SteppedStall, ManualClockStandingStillNeverEndsTheStream) {
  pliant::hal::ManualClock clock(100);
  EXPECT_FALSE(stalled_read_ends_stream(clock, [&clock] { ASSERT_EQ(clock.advance(0.5), HalStatus::ok); }))
      << "step_timeout_s of real time passed, the injected clock did not move";
  EXPECT_GE(real_wait_, std::chrono::milliseconds(200)) << "the read waited for the player (the real-time cap)";
  EXPECT_FALSE(camera_->stats().ended_early);
  // The caller's time goes on; the next read finds the end of the file OpenNI2 reported meanwhile.
  ASSERT_EQ(clock.advance(0.25), HalStatus::ok);
  DepthFrame frame;
  EXPECT_EQ(camera_->read(frame), HalStatus::no_data);
  EXPECT_TRUE(camera_->end_of_stream());
  EXPECT_TRUE(camera_->stats().ended_early);
  EXPECT_EQ(camera_->stats().last_frame_index, 11);
  EXPECT_EQ(camera_->counters().samples, 11u);
  EXPECT_EQ(camera_->stop(), HalStatus::ok);
  EXPECT_EQ(camera_->cleanup(), HalStatus::ok);
  camera_.reset();  // before the clock it refers to
}

// A clock that moves by a fixed step each time it is read moves during a blocking read, which a
// ManualClock cannot (its only thread is blocked): the same 0.2 s real wait ends the stream or
// not depending on how far the injected clock moved during it.
class SteppingClock final : public pliant::hal::Clock {
 public:
  SteppingClock(double start_s, double step_s) : now_s_(start_s), step_s_(step_s) {}
  double now_s() const noexcept override {
    const double t = now_s_;
    now_s_ += step_s_;
    return t;
  }

 private:
  mutable double now_s_;
  double step_s_;
};

TEST_F(Openni2SteppedStall, EndsOnlyWhenTheInjectedClockPassedTheStepTimeoutDuringTheRead) {
  // The stalled read reads the clock twice, on entry and after its wait.
  SteppingClock short_steps(100, 0.15);  // 0.15 s during the read: below step_timeout_s
  EXPECT_FALSE(stalled_read_ends_stream(short_steps, [] {}));
  EXPECT_GE(real_wait_, std::chrono::milliseconds(200));
  EXPECT_FALSE(camera_->stats().ended_early);
  EXPECT_EQ(camera_->stop(), HalStatus::ok);
  EXPECT_EQ(camera_->cleanup(), HalStatus::ok);

  camera_.reset();
  SteppingClock long_steps(100, 0.25);  // 0.25 s during the read: past step_timeout_s
  EXPECT_TRUE(stalled_read_ends_stream(long_steps, [] {}));
  EXPECT_TRUE(camera_->stats().ended_early);
  EXPECT_EQ(camera_->stats().last_frame_index, 11);
  EXPECT_EQ(camera_->stop(), HalStatus::ok);
  EXPECT_EQ(camera_->cleanup(), HalStatus::ok);
  camera_.reset();  // before the clocks it refers to
}

// With a SteadyClock the injected and the real deadline coincide: the read that times out ends it.
TEST(Openni2Recording, SteppedStallWithASteadyClockEndsInTheReadThatTimesOut) {
  pliant::test_support::TempDir dir("pliant_oni_");
  pliant::hal::SteadyClock clock;
  Openni2CameraConfig config = recording_config(write_undecodable_last_frame(dir));
  config.step_timeout_s = 0.2;
  Openni2Camera camera(clock, config);
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  ASSERT_EQ(camera.start(), HalStatus::ok);
  DepthFrame frame;
  for (int k = 1; k <= 11; ++k) ASSERT_EQ(camera.read(frame), HalStatus::ok) << "frame " << k;
  const double before = clock.now_s();
  EXPECT_EQ(camera.read(frame), HalStatus::no_data);
  EXPECT_GE(clock.now_s() - before, 0.2);
  EXPECT_TRUE(camera.end_of_stream());
  EXPECT_TRUE(camera.stats().ended_early);
  EXPECT_EQ(camera.stop(), HalStatus::ok);
  EXPECT_EQ(camera.cleanup(), HalStatus::ok);
}

// Real-time playback at 1/50 speed: the first frame comes after about 0.6 s of real time, the
// second 1.7 s later. The stall ends the stream only when the injected clock passes
// stall_timeout_s since the last frame, however much real time passes.
TEST(Openni2Recording, RealTimeStallEndsOnlyWhenTheInjectedClockPassesTheStallTimeout) {
  pliant::hal::ManualClock clock(50);
  Openni2CameraConfig config = recording_config(oni::fixture_path(), Openni2Playback::real_time);
  config.playback_speed = 0.02;
  config.stall_timeout_s = 20;  // above three frame intervals at this speed (3 x 1.67 s)
  Openni2Camera camera(clock, config);
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  ASSERT_EQ(camera.start(), HalStatus::ok);
  DepthFrame frame;
  HalStatus status = HalStatus::no_data;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while ((status = camera.read(frame)) == HalStatus::no_data && std::chrono::steady_clock::now() < give_up) {
    std::this_thread::sleep_for(std::chrono::milliseconds(2));  // real time only: the clock stays at 50
  }
  ASSERT_EQ(status, HalStatus::ok) << "no first frame within 10 s";
  EXPECT_EQ(frame.header.sequence, 1u);
  EXPECT_FALSE(camera.end_of_stream()) << "the silence before it was real time only";
  // Frame 2 comes about 1.7 s of real time later: these reads find nothing.
  ASSERT_EQ(clock.advance(19.9), HalStatus::ok);
  EXPECT_EQ(camera.read(frame), HalStatus::no_data);
  EXPECT_FALSE(camera.end_of_stream());
  ASSERT_EQ(clock.advance(0.2), HalStatus::ok);  // 20.1 s since the first frame
  EXPECT_EQ(camera.read(frame), HalStatus::no_data);
  EXPECT_TRUE(camera.end_of_stream());
  EXPECT_TRUE(camera.stats().ended_early);
  EXPECT_EQ(camera.stats().last_frame_index, 1);
  EXPECT_EQ(camera.stop(), HalStatus::ok);
  EXPECT_EQ(camera.cleanup(), HalStatus::ok);
}

TEST(Openni2Recording, StopAndStartContinueAndReconfigureReplays) {
  pliant::hal::ManualClock clock(10);
  Openni2Camera camera(clock, recording_config(oni::fixture_path()));
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  ASSERT_EQ(camera.start(), HalStatus::ok);
  DepthFrame frame;
  for (int k = 1; k <= 3; ++k) ASSERT_EQ(camera.read(frame), HalStatus::ok);
  const double third = frame.header.stamp_s;
  EXPECT_EQ(camera.stop(), HalStatus::ok);
  ASSERT_EQ(clock.advance(5), HalStatus::ok);  // 5 s stopped
  ASSERT_EQ(camera.start(), HalStatus::ok);
  ASSERT_EQ(camera.read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 4u);
  EXPECT_NEAR(frame.header.stamp_s - third, 5 + 0.03337, 1e-3) << "time stopped is added";
  EXPECT_EQ(camera.stop(), HalStatus::ok);
  EXPECT_EQ(camera.cleanup(), HalStatus::ok);

  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  ASSERT_EQ(camera.start(), HalStatus::ok);
  ASSERT_EQ(camera.read(frame), HalStatus::ok);
  EXPECT_EQ(frame.header.sequence, 1u);
  EXPECT_EQ(camera.stats().last_timestamp_us, 11680u);
}

// OpenNI2's player crashed in ~5 % of teardowns at the end of a file (see the driver header):
// many full cycles, each ending at the end of the file, must all come through.
TEST(Openni2Recording, RepeatedPlaythroughsTearDownCleanly) {
  pliant::hal::ManualClock clock;
  for (int cycle = 0; cycle < 8; ++cycle) {
    Openni2Camera camera(clock, recording_config(oni::fixture_path()));
    ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
    ASSERT_EQ(camera.start(), HalStatus::ok);
    DepthFrame frame;
    int frames = 0;
    while (camera.read(frame) == HalStatus::ok) ++frames;
    EXPECT_EQ(frames, 12) << "cycle " << cycle;
    EXPECT_TRUE(camera.end_of_stream());
    if (cycle % 2 == 0) {
      EXPECT_EQ(camera.stop(), HalStatus::ok);
      EXPECT_EQ(camera.cleanup(), HalStatus::ok);
    }  // odd cycles: the destructor tears down an active camera
  }
}

TEST(Openni2Recording, LifecycleFaults) {
  pliant::hal::ManualClock clock;
  Openni2Camera camera(clock, recording_config(oni::fixture_path()));
  DepthFrame frame;
  EXPECT_EQ(camera.read(frame), HalStatus::wrong_state) << "before configure";
  EXPECT_EQ(camera.start(), HalStatus::wrong_state);
  EXPECT_EQ(camera.stop(), HalStatus::wrong_state);
  EXPECT_EQ(camera.cleanup(), HalStatus::wrong_state);
  EXPECT_EQ(camera.width(), 0);
  EXPECT_FALSE(camera.end_of_stream());
  EXPECT_EQ(camera.counters().lifecycle_errors, 4u);
  ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
  EXPECT_EQ(camera.counters().lifecycle_errors, 0u) << "configure resets the counters";
  EXPECT_EQ(camera.read(frame), HalStatus::wrong_state) << "before start";
  EXPECT_EQ(camera.configure(), HalStatus::wrong_state);
  ASSERT_EQ(camera.start(), HalStatus::ok);
  EXPECT_EQ(camera.start(), HalStatus::wrong_state);
  EXPECT_EQ(camera.cleanup(), HalStatus::wrong_state) << "while active";
  EXPECT_EQ(camera.read(frame), HalStatus::ok);
  EXPECT_EQ(camera.stop(), HalStatus::ok);
  EXPECT_EQ(camera.read(frame), HalStatus::wrong_state) << "after stop";
  EXPECT_EQ(camera.counters().lifecycle_errors, 5u);
  EXPECT_EQ(camera.state(), LifecycleState::inactive);
  EXPECT_EQ(camera.cleanup(), HalStatus::ok);
  EXPECT_EQ(camera.state(), LifecycleState::unconfigured);
}

TEST(Openni2Recording, RefusesBadConfigurations) {
  pliant::hal::ManualClock clock;
  const auto refused = [&](Openni2CameraConfig config, const char* needle) {
    Openni2Camera camera(clock, config);
    EXPECT_EQ(camera.configure(), HalStatus::invalid_argument) << needle;
    EXPECT_NE(camera.last_error().find(needle), std::string::npos) << camera.last_error();
    EXPECT_EQ(camera.state(), LifecycleState::unconfigured);
  };
  Openni2CameraConfig c = recording_config(oni::fixture_path());
  c.location.clear();
  refused(c, "location");
  c = recording_config(oni::fixture_path());
  c.playback_speed = 0;
  refused(c, "playback_speed");
  c = recording_config(oni::fixture_path());
  c.step_timeout_s = std::nan("");
  refused(c, "step_timeout_s");
  c = recording_config(oni::fixture_path());
  c.teardown_grace_s = -1;
  refused(c, "teardown_grace_s");
  c = recording_config(oni::fixture_path());
  c.fps = 5000;
  refused(c, "fps");
  c = recording_config(oni::fixture_path());
  c.source = Openni2Source::device;
  refused(c, "stepped");
  c = recording_config(oni::fixture_path());
  c.fallback_intrinsics = DepthIntrinsics{-1, 500, 320, 240, 640, 480};
  refused(c, "fallback_intrinsics");
  c = recording_config("/tmp/" + std::string(300, 'x') + ".oni");
  refused(c, "255");
}

TEST(Openni2Recording, MissingFileIsAClearError) {
  pliant::hal::ManualClock clock;
  Openni2Camera camera(clock, recording_config("/nonexistent/dir/room.oni"));
  EXPECT_EQ(camera.configure(), HalStatus::io_error);
  EXPECT_EQ(camera.last_check(), OniCheck::io_error);
  EXPECT_NE(camera.last_error().find("/nonexistent/dir/room.oni"), std::string::npos) << camera.last_error();
  EXPECT_EQ(camera.state(), LifecycleState::unconfigured);
  DepthFrame frame;
  EXPECT_EQ(camera.read(frame), HalStatus::wrong_state);
}

TEST(Openni2Recording, TruncatedCopiesAreRefused) {
  pliant::hal::ManualClock clock;
  pliant::test_support::TempDir dir("pliant_oni_");
  const std::vector<std::uint8_t> full = oni::read_bytes(oni::fixture_path());
  for (std::size_t keep : {std::size_t{10}, std::size_t{5000}, full.size() / 2, full.size() - 1000, full.size() - 28}) {
    const std::string path = dir / ("cut_" + std::to_string(keep) + ".oni");
    oni::write_bytes(path, std::vector<std::uint8_t>(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(keep)));
    Openni2Camera camera(clock, recording_config(path));
    EXPECT_EQ(camera.configure(), HalStatus::io_error) << keep;
    EXPECT_EQ(camera.last_check(), keep < 24 ? OniCheck::too_short : OniCheck::truncated) << keep;
    EXPECT_NE(camera.last_error().find("recording refused"), std::string::npos) << camera.last_error();
  }
  // Not a recording at all.
  const std::string text = dir / "notes.oni";
  oni::write_bytes(text, std::vector<std::uint8_t>(100, 'a'));
  Openni2Camera camera(clock, recording_config(text));
  EXPECT_EQ(camera.configure(), HalStatus::io_error);
  EXPECT_EQ(camera.last_check(), OniCheck::bad_magic);
}

TEST(Openni2Recording, CorruptedNamesAreRefusedBeforeOpenNi2SeesThem) {
  pliant::hal::ManualClock clock;
  pliant::test_support::TempDir dir("pliant_oni_");
  std::vector<std::uint8_t> bytes = oni::read_bytes(oni::fixture_path());
  const std::size_t at = oni::find_text(bytes, "LowLightCompensation", true);
  ASSERT_NE(at, std::string::npos);
  bytes[at + 20] = 0xAE;  // this file crashes OpenNI2 2.2 when opened directly
  const std::string path = dir / "crasher.oni";
  oni::write_bytes(path, bytes);
  Openni2Camera camera(clock, recording_config(path));
  EXPECT_EQ(camera.configure(), HalStatus::io_error);
  EXPECT_EQ(camera.last_check(), OniCheck::bad_string);
}

// Damage inside the compressed frames passes the structural check: OpenNI2 decodes it into
// wrong pixels. Every such file must still play to its end without a crash.
TEST(Openni2Recording, DamagedFramePayloadsPlayWithoutCrashing) {
  pliant::hal::ManualClock clock;
  pliant::test_support::TempDir dir("pliant_oni_");
  const std::vector<std::uint8_t> full = oni::read_bytes(oni::fixture_path());
  std::vector<oni::Record> payloads;
  for (const oni::Record& r : oni::records(full)) {
    if (r.type == 0x0A) payloads.push_back(r);
  }
  ASSERT_EQ(payloads.size(), 24u);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 6; ++trial) {
    std::vector<std::uint8_t> bytes = full;
    for (int k = 0; k < 40; ++k) {
      const oni::Record& r = payloads[std::uniform_int_distribution<std::size_t>(0, payloads.size() - 1)(rng)];
      const std::size_t at = r.offset + r.fields + std::uniform_int_distribution<std::size_t>(0, r.payload - 1)(rng);
      bytes[at] = static_cast<std::uint8_t>(rng());
    }
    const std::string path = dir / ("damaged_" + std::to_string(trial) + ".oni");
    oni::write_bytes(path, bytes);
    Openni2CameraConfig config = recording_config(path);
    config.step_timeout_s = 2;  // a frame OpenNI2 cannot decode is skipped; if it was the last, a read times out
    Openni2Camera camera(clock, config);
    ASSERT_EQ(camera.configure(), HalStatus::ok) << camera.last_error();
    ASSERT_EQ(camera.start(), HalStatus::ok);
    DepthFrame frame;
    int delivered = 0;
    for (int k = 0; k < 20 && !camera.end_of_stream(); ++k) {
      if (camera.read(frame) == HalStatus::ok) {
        ++delivered;
      } else {
        ASSERT_EQ(clock.advance(config.step_timeout_s), HalStatus::ok);  // the loop's time goes on
      }
    }
    EXPECT_TRUE(camera.end_of_stream()) << "trial " << trial;
    const Openni2CameraStats stats = camera.stats();
    EXPECT_EQ(static_cast<std::uint64_t>(delivered) + stats.rejected, stats.received)
        << "every frame delivered or counted";
    EXPECT_EQ(camera.stop(), HalStatus::ok);
    EXPECT_EQ(camera.cleanup(), HalStatus::ok);
  }
}

}  // namespace
