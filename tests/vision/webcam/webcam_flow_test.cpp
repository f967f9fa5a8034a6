// Dense flow, the windowed mean of eq. 14, patch similarity and search, and the advector's
// checks on synthetic frames whose motion is known.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "pliant/vision/webcam_advection.hpp"
#include "pliant/vision/webcam_error.hpp"
#include "pliant/vision/webcam_flow.hpp"
#include "webcam_test_support.hpp"

namespace pliant::vision::webcam {
namespace {

// A flow field f(x, y) = (a x + b y + c, d x + e y + g).
cv::Mat affine_flow(int width, int height) {
  cv::Mat flow(height, width, CV_32FC2);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double fx = 0.01 * x - 0.02 * y + 1.5, fy = 0.03 * x + 0.01 * y - 2.0;
      flow.at<cv::Vec2f>(y, x) = cv::Vec2f(static_cast<float>(fx), static_cast<float>(fy));
    }
  }
  return flow;
}

TEST(webcam_flow, WindowMeanOfAnAffineFieldIsItsValueAtTheCentre) {
  const cv::Mat flow = affine_flow(64, 48);
  for (const cv::Point2d p : {cv::Point2d(20, 20), cv::Point2d(20.3, 17.8), cv::Point2d(31.5, 24.25)}) {
    for (int window : {1, 4, 10, 11}) {
      const cv::Point2d mean = window_mean_flow(flow, p, window);
      EXPECT_NEAR(mean.x, 0.01 * p.x - 0.02 * p.y + 1.5, 1e-5) << window;
      EXPECT_NEAR(mean.y, 0.03 * p.x + 0.01 * p.y - 2.0, 1e-5) << window;
    }
  }
}

TEST(webcam_flow, WindowMeanAveragesAndClampsAtTheEdges) {
  cv::Mat flow(10, 10, CV_32FC2, cv::Vec2f(0, 0));
  flow.at<cv::Vec2f>(5, 5) = cv::Vec2f(100, -100);
  // A 10 x 10 window with integer-aligned samples covers the spike once: 100 / 100.
  const cv::Point2d mean = window_mean_flow(flow, cv::Point2d(5.5, 5.5), 10);
  EXPECT_NEAR(mean.x, 1.0, 1e-9);
  EXPECT_NEAR(mean.y, -1.0, 1e-9);
  // Far outside the frame: the edge values, no crash.
  const cv::Mat constant(8, 8, CV_32FC2, cv::Vec2f(0.5f, 0.25f));
  const cv::Point2d outside = window_mean_flow(constant, cv::Point2d(-50.2, 300.7), 10);
  EXPECT_NEAR(outside.x, 0.5, 1e-9);
  EXPECT_NEAR(outside.y, 0.25, 1e-9);
}

TEST(webcam_flow, PatchSimilarity) {
  const cv::Mat texture = test::random_texture(64, 64, 3);
  cv::Mat a, b, c;
  extract_patch(texture, cv::Point2d(30, 30), 11, a);
  ASSERT_EQ(a.size(), cv::Size(11, 11));
  EXPECT_NEAR(patch_similarity(a, a), 1.0, 1e-9);
  b = a * 0.5 + 20;  // contrast and brightness
  EXPECT_NEAR(patch_similarity(a, b), 1.0, 1e-6);
  extract_patch(test::random_texture(64, 64, 4), cv::Point2d(30, 30), 11, c);
  EXPECT_LT(patch_similarity(a, c), 0.5);
  const cv::Mat flat(11, 11, CV_32F, cv::Scalar(100)), other_flat(11, 11, CV_32F, cv::Scalar(103));
  EXPECT_EQ(patch_similarity(flat, other_flat), 1.0);
  EXPECT_EQ(patch_similarity(flat, cv::Mat(11, 11, CV_32F, cv::Scalar(200))), 0.0);
  EXPECT_EQ(patch_similarity(flat, a), 0.0);
}

TEST(webcam_flow, SearchFindsASubPixelShift) {
  const cv::Mat texture = test::random_texture(80, 80, 5);
  cv::Mat templ;
  extract_patch(texture, cv::Point2d(40, 40), 11, templ);
  const cv::Mat moved = test::shifted(texture, 2.3, -1.6);
  const PatchMatch match = search_patch(moved, templ, cv::Point2d(40, 40), 4);
  EXPECT_GT(match.similarity, 0.95);
  EXPECT_NEAR(match.position.x, 42.3, 0.2);
  EXPECT_NEAR(match.position.y, 38.4, 0.2);
  // Out of reach: no good match.
  const PatchMatch far = search_patch(test::shifted(texture, 9, 0), templ, cv::Point2d(40, 40), 2);
  EXPECT_LT(far.similarity, 0.8);
}

class DenseFlowTest : public ::testing::TestWithParam<FlowMethod> {};

TEST_P(DenseFlowTest, RecoversATranslation) {
  const cv::Mat texture = test::random_texture(160, 120, 6);
  const cv::Mat moved = test::shifted(texture, 1.4, -0.7);
  DenseFlow flow(GetParam(), 1);
  EXPECT_EQ(flow.method(), GetParam());
  cv::Mat field;
  flow.compute(texture, moved, field);
  ASSERT_EQ(field.type(), CV_32FC2);
  ASSERT_EQ(field.size(), texture.size());
  const cv::Point2d mean = window_mean_flow(field, cv::Point2d(80, 60), 10);
  EXPECT_NEAR(mean.x, 1.4, 0.05);
  EXPECT_NEAR(mean.y, -0.7, 0.05);
}

INSTANTIATE_TEST_SUITE_P(Methods, DenseFlowTest, ::testing::Values(FlowMethod::dis, FlowMethod::farneback),
                         [](const ::testing::TestParamInfo<FlowMethod>& param) {
                           return flow_method_name(param.param);
                         });

TEST(webcam_flow, MethodNamesAndSettings) {
  EXPECT_EQ(parse_flow_method("dis"), FlowMethod::dis);
  EXPECT_EQ(parse_flow_method("farneback"), FlowMethod::farneback);
  EXPECT_THROW(parse_flow_method("lucas-kanade"), InputError);
  EXPECT_THROW(DenseFlow(FlowMethod::dis, 5), InputError);
  EXPECT_EQ(dis_finest_scale_for_spacing(100), 2);
  EXPECT_EQ(dis_finest_scale_for_spacing(40), 1);
  EXPECT_EQ(dis_finest_scale_for_spacing(30), 0);
  EXPECT_EQ(dis_finest_scale_for_spacing(0), 0);
  AdvectionConfig bad;
  bad.window_px = 0;
  EXPECT_THROW(check_advection_config(bad), InputError);
  bad = AdvectionConfig{};
  bad.patch_px = 10;
  EXPECT_THROW(check_advection_config(bad), InputError);
  bad = AdvectionConfig{};
  bad.fb_threshold_px = std::nan("");
  EXPECT_THROW(check_advection_config(bad), InputError);
  bad = AdvectionConfig{};
  bad.refresh_similarity = 0.5;
  EXPECT_THROW(check_advection_config(bad), InputError);
  for (int refine : {-1, 1, 2, 10, 53}) {
    bad = AdvectionConfig{};
    bad.refine_window_px = refine;
    EXPECT_THROW(check_advection_config(bad), InputError) << refine;
  }
  for (int margin : {-2, 0, 15, 4097}) {
    bad = AdvectionConfig{};
    bad.flow_margin_px = margin;
    EXPECT_THROW(check_advection_config(bad), InputError) << margin;
  }
  AdvectionConfig good;
  for (int margin : {-1, 16, 4096}) {
    good.flow_margin_px = margin;
    EXPECT_NO_THROW(check_advection_config(good)) << margin;
  }
  for (int refine : {0, 3, 9, 51}) {
    good.refine_window_px = refine;
    EXPECT_NO_THROW(check_advection_config(good)) << refine;
  }
}

// Three particles over a texture moving right by 1 px per frame; a grey square then covers the
// second one: it must not be observed while covered, and must be found again afterwards.
TEST(webcam_flow, AdvectorObservesMovingParticlesAndNotCoveredOnes) {
  const cv::Mat texture = test::random_texture(160, 120, 8);
  const std::vector<cv::Point2d> start = {{40, 60}, {80, 60}, {120, 60}};
  AdvectionConfig config;
  config.dis_finest_scale = 1;
  FlowAdvector advector(FlowMethod::dis, config);
  advector.start(texture, start);
  std::vector<cv::Point2d> positions = start;
  std::vector<std::uint8_t> seen(3, 1);
  std::vector<ParticleObservation> out;
  const cv::Rect cover(70, 45, 30, 30);
  for (int k = 1; k <= 8; ++k) {
    cv::Mat frame = test::shifted(texture, k, 0);
    const bool covered = k >= 3 && k <= 5;
    if (covered) frame(cover).setTo(cv::Scalar(128));
    std::vector<cv::Point2d> predicted(3);
    for (std::size_t i = 0; i < 3; ++i) predicted[i] = start[i] + cv::Point2d(k, 0);
    advector.observe(frame, positions, predicted, seen, out);
    ASSERT_EQ(out.size(), 3u);
    for (std::size_t i = 0; i < 3; ++i) {
      const bool hidden = covered && i == 1;
      EXPECT_EQ(out[i].usable(), !hidden)
          << "frame " << k << " particle " << i << " " << observation_kind_name(out[i].kind);
      if (out[i].usable()) {
        EXPECT_NEAR(out[i].position.x, start[i].x + k, 0.1) << k << " " << i;
        EXPECT_NEAR(out[i].position.y, start[i].y, 0.1) << k << " " << i;
        positions[i] = out[i].position;
      } else {
        EXPECT_TRUE(std::isnan(out[i].position.x));
        positions[i] = predicted[i];  // what a tracker would do
      }
      seen[i] = out[i].usable() ? 1 : 0;
    }
    if (k == 6) {
      EXPECT_EQ(out[1].kind, ObservationKind::found);
    }
    advector.commit(positions, seen);
  }
  EXPECT_EQ(advector.forward_flow().size(), advector.flow_region().size());
  EXPECT_EQ(advector.backward_flow().size(), advector.flow_region().size());
  EXPECT_EQ(advector.flow_region() & cv::Rect(cv::Point(0, 0), texture.size()), advector.flow_region());
}

// The flow region: the particles' bounding box grown by the margin, clipped to the frame; on a
// texture that moves and turns, particles advected in it land where the whole frame's flow
// puts them, to well under the tracking error.
TEST(webcam_flow, TheFlowRegionFollowsTheParticlesAndAdvectsAsTheWholeFrame) {
  const cv::Mat texture = test::random_texture(960, 540, 21);
  std::vector<cv::Point2d> start;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 8; ++c) start.emplace_back(330 + 40.0 * c, 200 + 40.0 * r);
  }
  AdvectionConfig roi;
  roi.flow_margin_px = 48;
  AdvectionConfig whole = roi;
  whole.flow_margin_px = -1;
  FlowAdvector in_region(FlowMethod::dis, roi), in_frame(FlowMethod::dis, whole);
  in_region.start(texture, start);
  in_frame.start(texture, start);
  std::vector<cv::Point2d> a = start, b = start;
  const std::vector<std::uint8_t> seen(start.size(), 1);
  std::vector<ParticleObservation> out_a, out_b;
  const cv::Point2f centre(480, 270);
  double worst = 0;
  for (int k = 1; k <= 6; ++k) {
    cv::Mat frame;
    const cv::Mat m = cv::getRotationMatrix2D(centre, 0.4 * k, 1.0 + 0.004 * k);
    cv::warpAffine(texture, frame, m, texture.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    in_region.observe(frame, a, a, seen, out_a);
    in_frame.observe(frame, b, b, seen, out_b);
    for (std::size_t i = 0; i < start.size(); ++i) {
      ASSERT_TRUE(out_a[i].usable() && out_b[i].usable()) << k << " " << i;
      worst = std::max(worst, cv::norm(out_a[i].position - out_b[i].position));
      a[i] = out_a[i].position;
      b[i] = out_b[i].position;
    }
    in_region.commit(a, seen);
    in_frame.commit(b, seen);
    const cv::Rect& region = in_region.flow_region();
    EXPECT_LE(region.x, 330 - 48 + 8);
    EXPECT_LT(region.area(), texture.size().area() / 2) << k;
    EXPECT_EQ(in_frame.flow_region(), cv::Rect(cv::Point(0, 0), texture.size()));
  }
  EXPECT_LT(worst, 0.05);
}

}  // namespace
}  // namespace pliant::vision::webcam
