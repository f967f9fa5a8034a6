// `pliant track-depth`: the rendered press (press_scene.hpp) written as 16-bit PNGs with a TUM
// style list and as `pliant record`'s depth_frames.csv, tracked by the binary, with a plan and
// with seeded particles; the real Kinect recording tests/data/oni_kinect/room.oni end to end
// (with drivers/openni2); exit statuses and one-line messages for malformed input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "cli/cli_test_support.hpp"
#include "pliant/host/recording.hpp"
#include "press_scene.hpp"

namespace pliant::cli_test {
namespace {

using vision::test::PressScene;

constexpr int kFrames = 40;  // 15 still frames, then the first 25 of the press

// Writes frames 0..kFrames-1 as PNGs (0.1 mm units), depth.txt, the same frames as a
// depth_frames.csv (scale and intrinsics in it) and the plan; returns the options that place the
// camera (pose, region, noise), without the intrinsics and scale.
std::string write_inputs(const PressScene& scene, const fs::path& root) {
  fs::create_directories(root / "depth");
  std::mt19937 rng(5);
  std::string list = "# depth maps\n# timestamp filename\n";
  std::string recorded = "index,t,file,depth_scale_m,fx,fy,cx,cy\n";
  for (int f = 0; f < kFrames; ++f) {
    const vision::DepthImage image = scene.image(f, rng);
    const cv::Mat mat(image.height, image.width, CV_16UC1, const_cast<std::uint16_t*>(image.data.data()));
    const std::string name = "depth/" + std::to_string(f) + ".png";
    if (!cv::imwrite((root / name).string(), mat)) throw std::runtime_error("cannot write " + name);
    char stamp[32];
    std::snprintf(stamp, sizeof stamp, "%.6f", scene.truth.recording.frame_times_s[static_cast<std::size_t>(f)]);
    list += std::string(stamp) + " " + name + "\n";
    recorded += std::to_string(f) + "," + stamp + "," + name + ",0.0001,525,525,319.5,239.5\n";
  }
  write_text(root / "depth.txt", list);
  write_text(root / "depth_frames.csv", recorded);
  host::write_recording(scene.plan, (root / "plan").string());
  const Eigen::Quaterniond q(scene.camera_to_world.linear());
  const Eigen::Vector3d t = scene.camera_to_world.translation();
  char pose[256];
  std::snprintf(pose, sizeof pose, "%.9f,%.9f,%.9f,%.12f,%.12f,%.12f,%.12f", t.x(), t.y(), t.z(), q.x(), q.y(), q.z(),
                q.w());
  const vision::PixelRect& r = scene.cloud.region;
  return " --noise 0.0005 --camera-pose " + std::string(pose) + " --region " + std::to_string(r.u0) + "," +
         std::to_string(r.v0) + "," + std::to_string(r.width) + "," + std::to_string(r.height);
}

class TrackDepthCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scene_ = new PressScene(0.5, 0.5e-3);
    root_ = new TempDir();
    placement_ = new std::string(write_inputs(*scene_, root_->path()));
    camera_ = new std::string(" --intrinsics 525,525,319.5,239.5 --units-per-metre 10000" + *placement_);
  }
  static void TearDownTestSuite() {
    delete camera_;
    delete placement_;
    delete root_;
    delete scene_;
  }
  static std::string inputs() {
    return quoted((root_->path() / "plan").string()) + " " + quoted((root_->path() / "depth.txt").string());
  }
  static PressScene* scene_;
  static TempDir* root_;
  static std::string* camera_;     // intrinsics, scale and placement
  static std::string* placement_;  // pose, region, noise
};
PressScene* TrackDepthCli::scene_ = nullptr;
TempDir* TrackDepthCli::root_ = nullptr;
std::string* TrackDepthCli::camera_ = nullptr;
std::string* TrackDepthCli::placement_ = nullptr;

// RMS distance of the observed particles 25.. (the ones that move) from the truth, m.
double observed_rms(const host::Recording& tracked, const PressScene& scene, long& count) {
  double sum = 0;
  count = 0;
  for (int f = 1; f < tracked.frame_count(); ++f) {
    for (int i = 25; i < tracked.particle_count; ++i) {
      if (!tracked.observed(f, i)) continue;
      const Eigen::Vector3d x(tracked.position(f, i, 0), tracked.position(f, i, 1), tracked.position(f, i, 2));
      sum += (x - scene.truth_at(f, i)).squaredNorm();
      ++count;
    }
  }
  return std::sqrt(sum / static_cast<double>(std::max(count, 1L)));
}

TEST_F(TrackDepthCli, TracksTheSequenceIntoARecording) {
  TempDir out;
  const CommandResult r = run_pliant("track-depth " + inputs() + *camera_ + " -o " + quoted(out / "tracked"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("wrote "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("15 calibration frames"), std::string::npos) << r.out;
  EXPECT_EQ(r.err, "");
  const host::Recording tracked = host::read_recording(out / "tracked");
  ASSERT_EQ(tracked.frame_count(), kFrames);
  ASSERT_EQ(tracked.particle_count, 100);
  EXPECT_TRUE(tracked.meta.contains("depth_tracking"));
  long count = 0;
  const double rms = observed_rms(tracked, *scene_, count);
  ASSERT_GT(count, 500);
  EXPECT_LT(rms, 0.25e-3);  // half the depth noise
  // An existing recording is not overwritten without --force.
  const CommandResult again = run_pliant("track-depth " + inputs() + *camera_ + " -o " + quoted(out / "tracked"));
  EXPECT_EQ(again.status, 2);
  EXPECT_NE(again.err.find("is not empty; pass --force"), std::string::npos) << again.err;
}

// The same frames listed as `pliant record` writes them: scale and intrinsics come from the list.
TEST_F(TrackDepthCli, RecordersDepthFramesCarryScaleAndIntrinsics) {
  TempDir out;
  const std::string plan = quoted((root_->path() / "plan").string());
  const CommandResult r =
      run_pliant("track-depth " + plan + " " + quoted((root_->path() / "depth_frames.csv").string()) + *placement_ +
                 " -o " + quoted(out / "t"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("(pliant record depth_frames.csv), 640x480, 0.1 mm per unit"), std::string::npos) << r.out;
  const host::Recording tracked = host::read_recording(out / "t");
  ASSERT_EQ(tracked.frame_count(), kFrames);
  long count = 0;
  EXPECT_LT(observed_rms(tracked, *scene_, count), 0.25e-3);
  EXPECT_GT(count, 500);
}

// No plan: particles seeded on the first frame's surface (the region holds the block and the
// table around it) are tracked; the seeds that lie on the block's top move with the press.
TEST_F(TrackDepthCli, SeededParticlesAreTrackedWithoutAPlan) {
  TempDir out;
  const CommandResult r = run_pliant("track-depth " + quoted((root_->path() / "depth.txt").string()) + *camera_ +
                                     " --seed-spacing 0.01 -o " + quoted(out / "seeded"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("seeded "), std::string::npos) << r.out;
  const host::Recording tracked = host::read_recording(out / "seeded");
  ASSERT_EQ(tracked.frame_count(), kFrames);
  EXPECT_GT(tracked.particle_count, 20);
  EXPECT_TRUE(tracked.fixed.empty());
  EXPECT_TRUE(tracked.driven.empty());
}

#ifdef PLIANT_TRACK_DEPTH_ONI
// The real Kinect recording (12 frames of a room with a static camera) through the whole depth
// path: .oni played by drivers/openni2, intrinsics from its field of view, millimetre depth,
// particles seeded every 10 cm, tracked. The person at the left of the image (columns below
// 200, 0.6 - 1.1 m away) moves by up to 15 mm over the 0.4 s; the rest of the room is still,
// so there the truth is that the particles stay where they were seeded: observed positions
// must stay within the Kinect v1's random depth error (about 1.5 mm x z^2, z in m: 1.5 mm at
// 1 m, 13 mm at 3 m; the plane fit averages 12 points).
TEST(TrackDepthOni, RealKinectRecordingRunsEndToEnd) {
  TempDir out;
  const CommandResult r =
      run_pliant("track-depth " + quoted(fs::path(PLIANT_TRACK_DEPTH_ONI)) +
                 " --seed-spacing 0.1 --reference-frames 0 --region 200,0,440,480 -o " + quoted(out / "room"));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("read 12 frames (OpenNI recording), 640x480, 1 mm per unit"), std::string::npos) << r.out;
  const host::Recording tracked = host::read_recording(out / "room");
  ASSERT_EQ(tracked.frame_count(), 12);
  ASSERT_GT(tracked.particle_count, 500);
  std::vector<double> motion;
  int observed_first = 0;
  for (int i = 0; i < tracked.particle_count; ++i) {
    const Eigen::Vector3d x0(tracked.position(0, i, 0), tracked.position(0, i, 1), tracked.position(0, i, 2));
    ASSERT_TRUE(x0.allFinite());
    ASSERT_GT(x0.z(), 0.3);  // in front of the camera, metres (a scale error would show here)
    ASSERT_LT(x0.z(), 10.0);
    observed_first += tracked.observed(1, i) ? 1 : 0;
    for (int f = 1; f < 12; ++f) {
      if (!tracked.observed(f, i)) continue;
      const Eigen::Vector3d x(tracked.position(f, i, 0), tracked.position(f, i, 1), tracked.position(f, i, 2));
      motion.push_back((x - x0).norm() / (1.5e-3 * x0.z() * x0.z()));
    }
  }
  EXPECT_GT(observed_first, tracked.particle_count / 4);
  ASSERT_GT(motion.size(), 11u * 300u);
  std::sort(motion.begin(), motion.end());
  const double p90 = motion[motion.size() * 9 / 10], p99 = motion[motion.size() * 99 / 100];
  std::printf(
      "room.oni: %d particles, %zu observed particle-frames; motion / Kinect depth sd: p90 %.2f, p99 %.2f, "
      "max %.2f\n",
      tracked.particle_count, motion.size(), p90, p99, motion.back());
  EXPECT_LT(p90, 1.0);
  EXPECT_LT(p99, 2.5);
  EXPECT_LT(motion.back(), 5.0);
}
#endif

TEST_F(TrackDepthCli, RoundsPrintTheirEstimates) {
  TempDir out;
  const CommandResult r = run_pliant("track-depth " + inputs() + *camera_ +
                                     " --rounds 2 --msm-beta 0.3 --all-tracked -o " + quoted(out / "t"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("round 1: prior msm_beta 0.3 -> estimate"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("every tracked position"), std::string::npos) << r.out;
}

TEST_F(TrackDepthCli, MalformedInputIsOneLineAndStatusTwo) {
  TempDir out;
  auto expect_usage = [&](const std::string& arguments, const std::string& message) {
    const CommandResult r = run_pliant("track-depth " + arguments + " -o " + quoted(out / "x"));
    EXPECT_EQ(r.status, 2) << arguments << "\n" << r.out << r.err;
    EXPECT_EQ(r.err_lines().size(), 1u) << r.err;
    EXPECT_NE(r.err.find(message), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out.path() / "x" / "recording.json"));
  };
  const std::string plan = quoted((root_->path() / "plan").string());
  const std::string list = quoted((root_->path() / "depth.txt").string());
  expect_usage(inputs(), "depth.txt: the TUM list states no intrinsics; give --intrinsics FX,FY,CX,CY");
  expect_usage(inputs() + *camera_ + " --seed-spacing 0.01", "give either PLAN or --seed-spacing, not both");
  expect_usage(list + *camera_, "give PLAN (a recording of the particles) or --seed-spacing M");
  expect_usage(list + *camera_ + " --seed-spacing -1", "--seed-spacing must be > 0 m");
  expect_usage(list + *camera_ + " --seed-spacing nan", "--seed-spacing must be > 0 m");
  expect_usage(inputs() + " --intrinsics 525,525,319.5", "intrinsics: cy is missing");
  expect_usage(inputs() + " --intrinsics 0,525,319.5,239.5", "fx must be finite and > 0");
  expect_usage(inputs() + " --intrinsics 525,525,319.5,239.5 --units-per-metre -1", "--units-per-metre must be > 0");
  expect_usage(inputs() + *camera_ + " --rounds 0", "--rounds must be between 1 and 10");
  expect_usage(inputs() + *camera_ + " --msm-beta 2", "--msm-beta must be in [0, 1]");
  expect_usage(inputs() + *camera_ + " --correspondence edge", "--correspondence must be plane or point");
  expect_usage(inputs() + " --intrinsics 525,525,319.5,239.5 --camera-pose 0,0,0,0,0,0,3",
               "quaternion must have norm 1");
  expect_usage(inputs() + " --intrinsics 525,525,319.5,239.5 --region 600,0,100,10", "is not inside the 640x480 image");
  expect_usage(plan + " " + quoted((root_->path() / "missing.txt").string()) + *camera_, "missing.txt: cannot open");
  expect_usage(quoted((root_->path() / "no-plan").string()) + " " + list + *camera_, "no-plan");

  // A list naming a corrupt PNG, one naming an 8-bit PNG, one with a frame of another size.
  const fs::path bad = root_->path() / "bad";
  fs::create_directories(bad);
  write_text(bad / "corrupt.png", "\x89PNG\r\n\x1a\nnot really");
  cv::imwrite((bad / "eight.png").string(), cv::Mat(480, 640, CV_8UC1, cv::Scalar(9)));
  cv::imwrite((bad / "small.png").string(), cv::Mat(240, 320, CV_16UC1, cv::Scalar(3000)));
  fs::copy_file(root_->path() / "depth" / "0.png", bad / "first.png");
  write_text(bad / "corrupt.txt", "0 corrupt.png\n");
  write_text(bad / "eight.txt", "0 eight.png\n");
  write_text(bad / "sizes.txt", "0 first.png\n0.1 small.png\n");
  write_text(bad / "order.txt", "0.2 first.png\n0.1 first.png\n");
  expect_usage(plan + " " + quoted((bad / "corrupt.txt").string()) + *camera_, "corrupt.png: corrupt PNG (");
  expect_usage(plan + " " + quoted((bad / "eight.txt").string()) + *camera_, "must be 16-bit");
  expect_usage(plan + " " + quoted((bad / "sizes.txt").string()) + *camera_,
               "depth image is 320x240 but the intrinsics are for 640x480");
  expect_usage(plan + " " + quoted((bad / "order.txt").string()) + *camera_,
               "order.txt:2: timestamp '0.1' does not follow");
  // An .oni that is not one: refused before OpenNI2 parses it (or, without drivers/openni2,
  // because the build cannot read .oni at all).
  write_text(bad / "junk.oni", "NI10 is not enough");
  expect_usage(plan + " " + quoted((bad / "junk.oni").string()) + *camera_, "junk.oni: ");
  // A recorder's list whose scale is broken.
  write_text(bad / "depth_frames.csv",
             "index,t,file,depth_scale_m,fx,fy,cx,cy\n0,0,first.png,-1,525,525,319.5,239.5\n");
  expect_usage(plan + " " + quoted((bad / "depth_frames.csv").string()) + *placement_,
               "depth_frames.csv:2: depth_scale_m '-1' is not a positive number");

  // A 2D plan (pixels) cannot be tracked in depth.
  const CommandResult made = run_pliant("simulate foam_press -o " + quoted(out / "flat"));
  ASSERT_EQ(made.status, 0) << made.err;
  expect_usage(quoted(out / "flat") + " " + list + *camera_, "plan recording: must be 3D");
}

}  // namespace
}  // namespace pliant::cli_test
