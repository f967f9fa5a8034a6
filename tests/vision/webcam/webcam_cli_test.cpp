// `pliant track` run as a program on rendered PNG frames: the whole chain to `pliant estimate`,
// resampling, a video file, and every malformed input it must refuse cleanly.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/videoio.hpp>

#include "press_scene.hpp"
#include "pliant/host/recording.hpp"
#include "webcam_test_support.hpp"

namespace pliant::vision::webcam {
namespace {

namespace fs = std::filesystem;
using test::TempDir;

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string quoted(const std::string& text) {
  std::string out = "'";
  for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

struct CommandResult {
  int status = -1;
  std::string out, err;
};

CommandResult run_pliant(const std::string& arguments) {
  TempDir capture;
  const std::string command = quoted(PLIANT_EXE) + " " + arguments + " </dev/null >" + quoted(capture / "out") + " 2>" +
                              quoted(capture / "err");
  const int raw = std::system(command.c_str());
  CommandResult r;
  r.status = raw != -1 && WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = read_text(capture / "out");
  r.err = read_text(capture / "err");
  return r;
}

// The press scene rendered once per program into frame_000.png ...
struct RenderedPress {
  TempDir dir;
  test::PressScene scene{test::PressSceneConfig{}};
  std::vector<cv::Mat> frames;
  RenderedPress() {
    frames = scene.render_all();
    for (std::size_t k = 0; k < frames.size(); ++k)
      test::write_png(dir / cv::format("frame_%03d.png", static_cast<int>(k)), frames[k]);
  }
  std::string pattern() const { return dir / "frame_%03d.png"; }
  std::string region() const { return " --roi " + scene.roi() + " --grid " + scene.grid(); }
};

const RenderedPress& press() {
  static const auto rendered = std::make_unique<RenderedPress>();
  return *rendered;
}

// Exit status 2, the error on stderr's last line under "pliant track: " naming `part`, and no
// recording (nor a temporary directory) left in `parent`.
void expect_refused(const CommandResult& r, const std::string& part, const fs::path& parent) {
  EXPECT_EQ(r.status, 2) << r.err;
  const std::vector<std::string> lines = lines_of(r.err);
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines.back().rfind("pliant track: ", 0), 0u) << r.err;
  EXPECT_TRUE(contains(lines.back(), part)) << r.err;
  EXPECT_EQ(r.out, "");
  for (const auto& entry : fs::directory_iterator(parent)) {
    const std::string name = entry.path().filename().string();
    EXPECT_FALSE(contains(name, "rec")) << "left behind: " << name;
  }
}

TEST(webcam_cli, TrackThenEstimateRecoversTheRenderedMsmBeta) {
  const RenderedPress& p = press();
  TempDir dir;
  const std::string rec = dir / "rec";
  const CommandResult r =
      run_pliant("track " + quoted(p.pattern()) + " --fps 10" + p.region() + " -q -o " + quoted(rec));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_TRUE(contains(r.out, "wrote " + rec + ": 32 particles (4x8 grid) x 30 frames at 10 Hz, dis flow")) << r.out;
  EXPECT_TRUE(contains(r.out, "support: 24,25,26,27,28,29,30,31 (detected: bottom side)")) << r.out;
  EXPECT_TRUE(contains(r.out, "driven: 4 (detected: largest motion 1")) << r.out;

  const host::Recording recording = host::read_recording(rec);
  EXPECT_EQ(recording.length_unit, "px");
  EXPECT_EQ(recording.dimension, 2);
  EXPECT_EQ(recording.particle_count, 32);
  EXPECT_EQ(recording.frame_count(), 30);
  EXPECT_EQ(recording.fixed, p.scene.base());
  ASSERT_EQ(recording.driven.size(), 1u);
  EXPECT_EQ(recording.driven[0].id, p.scene.tool());
  EXPECT_TRUE(fs::exists(fs::path(rec) / "track.csv"));
  EXPECT_NEAR(recording.position(29, 4, 1), p.scene.truth(29, 4).y, 1.0);

  const CommandResult estimate = run_pliant("estimate " + quoted(rec) + " --json -");
  ASSERT_EQ(estimate.status, 0) << estimate.err;
  const nlohmann::json document = nlohmann::json::parse(estimate.out);
  const double beta = document.at("parameters").at("msm_beta").get<double>();
  std::printf("pliant track + pliant estimate: msm_beta %.4f (rendered %.2f)\n", beta, p.scene.config().msm_beta);
  EXPECT_NEAR(beta, p.scene.config().msm_beta, 0.05);
}

TEST(webcam_cli, GlobWithResamplingAndGivenRoles) {
  const RenderedPress& p = press();
  TempDir dir;
  const std::string rec = dir / "rec";
  const CommandResult r = run_pliant("track " + quoted(p.dir / "*.png") + " --fps 10 --rate 5 --flow farneback" +
                                     p.region() + " --support bottom --driven 4 -q -o " + quoted(rec));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "x 15 frames at 5 Hz, farneback flow")) << r.out;
  EXPECT_TRUE(contains(r.out, "(given)")) << r.out;
  const host::Recording recording = host::read_recording(rec);
  ASSERT_EQ(recording.frame_count(), 15);
  EXPECT_NEAR(recording.frame_times_s[1], 0.2, 1e-12);
  EXPECT_EQ(recording.meta.at("track").at("rate_hz"), 5.0);
  EXPECT_EQ(recording.meta.at("track").at("support"), "given");
}

TEST(webcam_cli, VideoFileInput) {
  const RenderedPress& p = press();
  TempDir dir;
  const std::string video = dir / "press.avi";
  {
    cv::VideoWriter writer(video, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, p.frames[0].size(), false);
    ASSERT_TRUE(writer.isOpened());
    for (int k = 0; k < 12; ++k) writer.write(p.frames[static_cast<std::size_t>(k)]);
  }
  const std::string rec = dir / "rec";
  const CommandResult r = run_pliant("track " + quoted(video) + p.region() + " --driven 112,70 -q -o " + quoted(rec));
  ASSERT_EQ(r.status, 0) << r.err;
  const host::Recording recording = host::read_recording(rec);
  EXPECT_EQ(recording.frame_count(), 12);
  EXPECT_EQ(recording.driven[0].id, 2);  // the particle nearest to (112, 70): (114.5, 74.5)
  EXPECT_EQ(recording.meta.at("camera"), "320x240 @ 10 Hz");
}

TEST(webcam_cli, MalformedInputIsRefusedAndWritesNothing) {
  const RenderedPress& p = press();
  TempDir dir;
  const std::string rec = dir / "rec";
  const std::string region = p.region();
  const std::string out = " -q -o " + quoted(rec);

  test::write_bytes(dir / "garbage.avi", std::string(2048, '\x13'));
  expect_refused(run_pliant("track " + quoted(dir / "garbage.avi") + region + out),
                 "garbage.avi: cannot open the video", dir.path());
  expect_refused(run_pliant("track " + quoted(dir / "missing.avi") + region + out), "missing.avi: no such file",
                 dir.path());
  expect_refused(run_pliant("track " + quoted(dir / "none_%03d.png") + region + out), "no file for number 0 or 1",
                 dir.path());
  expect_refused(run_pliant("track " + quoted(p.pattern()) + " --roi 10,10,0,20" + out), "empty region", dir.path());
  expect_refused(run_pliant("track " + quoted(p.pattern()) + " --roi 300,10,50,50" + out),
                 "reaches outside the 320x240 frame", dir.path());
  expect_refused(run_pliant("track " + quoted(p.pattern()) + out), "give the region", dir.path());
  expect_refused(run_pliant("track " + quoted(p.pattern()) + " --roi 1,2,3" + out), "--roi: expected x,y,w,h",
                 dir.path());
  expect_refused(run_pliant("track " + quoted(p.pattern()) + region + " --flow lk" + out), "--flow: expected",
                 dir.path());
  expect_refused(run_pliant("track " + quoted(p.pattern()) + region + " --flow-margin 8" + out),
                 "--flow-margin must be 16..4096 px, or -1", dir.path());
  expect_refused(run_pliant("track " + quoted(p.pattern()) + region + " --fps 10 --rate 20" + out),
                 "--rate 20 Hz is above the source's 10", dir.path());
  expect_refused(run_pliant("track " + quoted(p.pattern()) + region + " --support 1,x" + out), "--support: expected",
                 dir.path());
  expect_refused(run_pliant("track " + quoted(p.pattern()) + region + " --driven 99" + out),
                 "--driven: particle 99 out of range 0..31", dir.path());
  expect_refused(run_pliant("track " + quoted(p.pattern()) + " --roi 1,2,3,4 --mask m.png" + out), "excludes",
                 dir.path());

  // Masks: of another size, and empty.
  test::write_png(dir / "small_mask.png", cv::Mat(10, 10, CV_8UC1, cv::Scalar(255)));
  expect_refused(run_pliant("track " + quoted(p.pattern()) + " --mask " + quoted(dir / "small_mask.png") + out),
                 "mask is 10x10, the frames are 320x240", dir.path());
  test::write_png(dir / "empty_mask.png", cv::Mat(240, 320, CV_8UC1, cv::Scalar(0)));
  expect_refused(run_pliant("track " + quoted(p.pattern()) + " --mask " + quoted(dir / "empty_mask.png") + out),
                 "empty region", dir.path());

  // A sequence with a frame of another size, and one with a damaged frame, in the middle.
  fs::create_directory(dir / "sized");
  fs::create_directory(dir / "damaged");
  for (int k = 0; k < 6; ++k) {
    const cv::Mat& frame = p.frames[static_cast<std::size_t>(k)];
    test::write_png(dir / cv::format("sized/f_%d.png", k), k == 4 ? frame(cv::Rect(0, 0, 300, 240)) : frame);
    if (k == 3) {
      test::write_bytes(dir / "damaged/f_3.png", "\x89PNG\r\n\x1a\nbroken");
    } else {
      test::write_png(dir / cv::format("damaged/f_%d.png", k), frame);
    }
  }
  expect_refused(run_pliant("track " + quoted(dir / "sized/f_%d.png") + region + out),
                 "f_4.png: 300x240, the first frame is 320x240", dir.path());
  expect_refused(run_pliant("track " + quoted(dir / "damaged/f_%d.png") + region + out),
                 "f_3.png: cannot read the image", dir.path());

  // Nothing moves, roles to detect: refused.
  fs::create_directory(dir / "still");
  for (int k = 0; k < 4; ++k) test::write_png(dir / cv::format("still/f_%d.png", k), p.frames[0]);
  expect_refused(run_pliant("track " + quoted(dir / "still/f_%d.png") + region + out), "nothing moved", dir.path());

  // An existing, non-empty output directory is refused before tracking and left as it was.
  fs::create_directory(dir / "busy");
  test::write_bytes(dir / "busy/keep.txt", "keep");
  const CommandResult busy = run_pliant("track " + quoted(p.pattern()) + region + " -q -o " + quoted(dir / "busy"));
  EXPECT_EQ(busy.status, 2);
  EXPECT_TRUE(contains(busy.err, "is not empty")) << busy.err;
  EXPECT_EQ(read_text(dir / "busy/keep.txt"), "keep");
}

}  // namespace
}  // namespace pliant::vision::webcam
