// The webcam tracker against a rendered press whose particle paths and msm_beta are known
// (press_scene.hpp): tracking error, detected roles, msm_beta through the estimator, and a
// moving occluder.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "press_scene.hpp"
#include "pliant/host/estimate.hpp"
#include "pliant/vision/webcam_recording.hpp"
#include "pliant/vision/webcam_tracker.hpp"

namespace pliant::vision::webcam {
namespace {

constexpr double kBetaTolerance = 0.05;

test::PressSceneConfig occluded_config() {
  test::PressSceneConfig config;
  // 40 x 50 px, over rows 1 and 2 (y 104.5 and 134.5), crossing the grid at 10 px per frame
  // while the press goes on: each particle of those rows is hidden for about 4 frames.
  config.occluder_width = 40;
  config.occluder_height = 50;
  config.occluder_y = 95;
  config.occluder_x0 = 0;
  config.occluder_speed_px = 10;
  config.occluder_from = 4;
  return config;
}

struct Tracked {
  test::PressScene scene;
  TrackResult result;
};

Tracked track_scene(const test::PressSceneConfig& config, FlowMethod method, int refine_window_px = 9,
                    int peak_refine_window_px = 3) {
  test::PressScene scene(config);
  MemoryFrameSource source(scene.render_all(), config.rate_hz, "press scene");
  FrameReader reader(source, 0);
  TrackOptions options;
  options.flow = method;
  options.advection.refine_window_px = refine_window_px;
  options.advection.peak_refine_window_px = peak_refine_window_px;
  TrackResult result = track_particles(reader, parse_roi(scene.roi()), parse_grid(scene.grid()), options);
  return {std::move(scene), std::move(result)};
}

double error_px(const Tracked& t, int frame, int id) {
  const cv::Point2d d = t.result.tracked[t.result.at(frame, id)] - t.scene.truth(frame, id);
  return std::hypot(d.x, d.y);
}

struct ErrorSummary {
  double median = 0, p90 = 0, max = 0;
};

ErrorSummary summarize(const Tracked& t) {
  std::vector<double> errors;
  for (int f = 0; f < t.result.frame_count(); ++f) {
    for (int i = 0; i < t.result.particle_count(); ++i) errors.push_back(error_px(t, f, i));
  }
  std::sort(errors.begin(), errors.end());
  return {errors[errors.size() / 2], errors[errors.size() * 9 / 10], errors.back()};
}

double estimated_beta(const TrackResult& result) {
  const host::Recording recording = track_recording(result, "press");
  return host::estimate_recording(recording, host::EstimateOptions{}).result.msm_beta;
}

void expect_press_roles(const Tracked& t) {
  EXPECT_TRUE(t.result.roles.support_detected);
  EXPECT_EQ(t.result.roles.support_side, GridSide::bottom);
  EXPECT_EQ(t.result.roles.support, t.scene.base());
  EXPECT_TRUE(t.result.roles.driven_detected);
  EXPECT_EQ(t.result.roles.driven, t.scene.tool());
}

TEST(webcam_truth, PressIsTrackedWithinHalfAPixelAndGivesItsMsmBeta) {
  const test::PressSceneConfig config;
  const Tracked t = track_scene(config, FlowMethod::dis);
  ASSERT_EQ(t.result.frame_count(), t.scene.frame_count());
  ASSERT_EQ(t.result.particle_count(), t.scene.particle_count());
  // The tracker starts from the seeds, which the scene puts on its particles.
  for (int i = 0; i < t.result.particle_count(); ++i) EXPECT_LT(error_px(t, 0, i), 1e-9);
  const ErrorSummary e = summarize(t);
  std::printf("DIS press: error median %.3f px, p90 %.3f px, max %.3f px (tool moves %.1f px)\n", e.median, e.p90,
              e.max, config.depth_px);
  EXPECT_LE(e.median, 0.5);
  EXPECT_LE(e.max, 1.5);
  expect_press_roles(t);
  const double beta = estimated_beta(t.result);
  std::printf("DIS press: msm_beta %.4f (rendered %.2f)\n", beta, config.msm_beta);
  EXPECT_NEAR(beta, config.msm_beta, kBetaTolerance);
}

TEST(webcam_truth, FarnebackTracksThePressToo) {
  const test::PressSceneConfig config;
  const Tracked t = track_scene(config, FlowMethod::farneback);
  const ErrorSummary e = summarize(t);
  std::printf("Farneback press: error median %.3f px, p90 %.3f px, max %.3f px\n", e.median, e.p90, e.max);
  EXPECT_LE(e.median, 0.5);
  expect_press_roles(t);
  const double beta = estimated_beta(t.result);
  std::printf("Farneback press: msm_beta %.4f (rendered %.2f)\n", beta, config.msm_beta);
  EXPECT_NEAR(beta, config.msm_beta, kBetaTolerance);
}

// Softer and stiffer objects than the default scene, with noisier frames (grey sd 3): the chain
// must hold msm_beta over the range, not just at one value. Without the Lucas-Kanade refinement
// the flow's smoothing of the peak under the tool pushes a rendered 0.2 to about 0.30.
struct BetaCase {
  double msm_beta;
  double noise_grey;
};

class webcam_truth_beta : public ::testing::TestWithParam<BetaCase> {};

TEST_P(webcam_truth_beta, ChainRecoversTheRenderedMsmBeta) {
  test::PressSceneConfig config;
  config.msm_beta = GetParam().msm_beta;
  config.noise_grey = GetParam().noise_grey;
  const Tracked t = track_scene(config, FlowMethod::dis);
  const ErrorSummary e = summarize(t);
  expect_press_roles(t);
  EXPECT_LE(e.median, 0.5);
  const double beta = estimated_beta(t.result);
  std::printf("msm_beta %.2f, noise %.0f grey: error median %.3f px, max %.3f px; estimated %.4f\n", config.msm_beta,
              config.noise_grey, e.median, e.max, beta);
  EXPECT_NEAR(beta, config.msm_beta, kBetaTolerance);
}

INSTANTIATE_TEST_SUITE_P(range, webcam_truth_beta, ::testing::Values(BetaCase{0.2, 3}, BetaCase{0.8, 3}),
                         [](const ::testing::TestParamInfo<BetaCase>& param) {
                           return "beta_" + std::to_string(static_cast<int>(param.param.msm_beta * 100));
                         });

// The refinement is what removes the bias: with it off (eq. 14 alone) the soft object comes
// out clearly softer than rendered, with it on within the tolerance (the test above).
TEST(webcam_truth, WithoutRefinementTheFlowSmoothingBiasesMsmBetaUp) {
  test::PressSceneConfig config;
  config.msm_beta = 0.2;
  config.noise_grey = 3;
  const Tracked plain = track_scene(config, FlowMethod::dis, 0);
  const double beta = estimated_beta(plain.result);
  std::printf("msm_beta 0.2 without refinement: %.4f\n", beta);
  EXPECT_GT(beta, config.msm_beta + kBetaTolerance);
}

// A larger scene at 64 px spacing, where DIS resolves the flow two pyramid levels down (32 px
// patches in the frame, the setting of the 1920 x 1080 benchmark): eq. 14 alone gives about
// 0.38 for a rendered 0.2 here; the refinement works at full resolution whatever the level.
TEST(webcam_truth, CoarseFlowLevelIsRefinedAtFullResolution) {
  test::PressSceneConfig config;
  config.width = 640;
  config.height = 400;
  config.spacing_px = 64;
  config.x0 = 96.5;
  config.y0 = 100.5;
  config.depth_px = 20;
  config.msm_beta = 0.2;
  const Tracked t = track_scene(config, FlowMethod::dis);
  EXPECT_EQ(t.result.options.advection.dis_finest_scale, 2);
  expect_press_roles(t);
  const ErrorSummary e = summarize(t);
  const double beta = estimated_beta(t.result);
  std::printf("64 px spacing, DIS level 2: error median %.3f px, max %.3f px; msm_beta %.4f (rendered 0.2)\n", e.median,
              e.max, beta);
  EXPECT_LE(e.median, 0.5);
  EXPECT_NEAR(beta, config.msm_beta, kBetaTolerance);
}

TEST(webcam_truth, OccludedParticlesAreUnobservedWhileHiddenAndRecoveredAfter) {
  const test::PressSceneConfig config = occluded_config();
  const Tracked t = track_scene(config, FlowMethod::dis);
  const TrackResult& r = t.result;
  const int frames = r.frame_count();
  int hidden_frames = 0, recovered = 0, hidden_particles = 0;
  for (int i = 0; i < r.particle_count(); ++i) {
    int last_hidden = -1;
    for (int f = 0; f < frames; ++f) {
      // Fully hidden: its appearance patch (11 px) is inside the occluder.
      if (t.scene.hidden(f, i, -6)) {
        ++hidden_frames;
        last_hidden = f;
        EXPECT_EQ(r.observed[r.at(f, i)], 0) << "particle " << i << " frame " << f << " is hidden but observed";
      }
      // The tracker never loses it: bounded by a tenth of the spacing throughout.
      EXPECT_LT(error_px(t, f, i), 0.1 * config.spacing_px) << "particle " << i << " frame " << f;
    }
    if (last_hidden < 0) continue;
    ++hidden_particles;
    // Clear of the occluder (and its flow) from some frame on: observed again within 3 frames.
    int clear_from = -1;
    for (int f = last_hidden + 1; f < frames && clear_from < 0; ++f) {
      if (!t.scene.hidden(f, i, 12)) clear_from = f;
    }
    if (clear_from < 0 || clear_from + 3 >= frames) continue;
    bool seen_again = false;
    for (int f = clear_from; f <= clear_from + 3; ++f) seen_again = seen_again || r.observed[r.at(f, i)] != 0;
    EXPECT_TRUE(seen_again) << "particle " << i << " not recovered after frame " << clear_from;
    EXPECT_EQ(r.observed[r.at(frames - 1, i)], 1) << "particle " << i << " unobserved at the end";
    recovered += seen_again ? 1 : 0;
  }
  std::printf("occluder: %d particles hidden for %d particle-frames, %d recovered\n", hidden_particles, hidden_frames,
              recovered);
  EXPECT_GE(hidden_particles, 10);  // the scene does hide most of two rows
  EXPECT_GE(recovered, 8);
  const ErrorSummary e = summarize(t);
  std::printf("occluder: error median %.3f px, p90 %.3f px, max %.3f px\n", e.median, e.p90, e.max);
  EXPECT_LE(e.median, 0.5);
  expect_press_roles(t);
  const double beta = estimated_beta(r);
  std::printf("occluder: msm_beta %.4f (rendered %.2f)\n", beta, config.msm_beta);
  EXPECT_NEAR(beta, config.msm_beta, kBetaTolerance);
}

// A sharp press (a stiff-clustered object, msm_beta 0.2, pressed deep) peaks under the tool: a
// window averages that peak down, every frame, and the tool's path comes out short. The tool's
// particle gets the narrow window; its error at the end of the press must be well under what
// the common window leaves.
TEST(webcam_truth, TheToolsNarrowWindowFollowsTheDisplacementPeak) {
  test::PressSceneConfig config;
  config.msm_beta = 0.2;
  config.depth_px = 18;
  config.bilinear = true;
  const Tracked narrow = track_scene(config, FlowMethod::dis, 9, 3);
  const Tracked common = track_scene(config, FlowMethod::dis, 9, 9);
  const int last = narrow.result.frame_count() - 1;
  const int tool = narrow.scene.tool();
  const double narrow_error = error_px(narrow, last, tool);
  const double common_error = error_px(common, last, tool);
  std::printf("tool particle after an 18 px press, msm_beta 0.2: error %.3f px (3 px window), %.3f px (9 px)\n",
              narrow_error, common_error);
  EXPECT_LT(narrow_error, 0.7 * common_error);
}

}  // namespace
}  // namespace pliant::vision::webcam
