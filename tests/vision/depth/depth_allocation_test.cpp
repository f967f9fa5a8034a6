// What a depth tracker frame allocates once warmed up: nothing through operator new, and only
// nanoflann's kd-tree node pool through malloc (freed and re-malloced by every buildIndex).
#include "support/counting_allocator.hpp"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "pliant/vision/depth_recording.hpp"
#include "pliant/vision/depth_tracker.hpp"
#include "press_scene.hpp"

namespace pliant::vision {
namespace {

TEST(DepthTrackerAllocation, OnlyTheKdTreePoolPerFrame) {
  const test::PressScene scene(0.5, 0.5e-3);
  auto model = host::build_msm_model<3>(scene.plan, host::MsmSetupOptions{});
  DepthTrackerConfig config;
  config.cloud = scene.cloud;
  config.camera_to_world = scene.camera_to_world;
  config.depth_noise_m = scene.noise_m;
  MsmParams<3, double> params = host::base_params<3>(scene.plan, 1.0);
  params.msm_beta = 0.5;
  DepthTracker tracker(model->model, params, scene.intrinsics, config);
  std::mt19937 rng(3);
  std::vector<DepthImage> frames;
  for (int f = 0; f < 12; ++f) frames.push_back(scene.image(f, rng));
  std::vector<int> ids;
  std::vector<Eigen::Vector3d> targets;
  std::vector<DepthFrameReport> reports(frames.size());
  // Warm-up: nanoflann's index array (a std::vector) grows to the largest cloud it has seen;
  // calibrating on every frame once shows it the largest.
  for (const DepthImage& frame : frames) tracker.calibrate(frame.view());
  tracker.clear_calibration();
  tracker.calibrate(frames[0].view());
  auto step = [&](int f) {
    driven_targets_at(scene.plan, scene.truth.recording.frame_times_s[static_cast<std::size_t>(f)], ids, targets);
    const MsmDrivenTargets<3, double> driven{ids.data(), targets.data(), static_cast<int>(ids.size())};
    reports[static_cast<std::size_t>(f)] =
        tracker.update(frames[static_cast<std::size_t>(f)].view(), scene.dt(f), driven);
  };
  step(1);
  ids.reserve(4);
  targets.reserve(4);
  ::pliant::test::AllocationCounts counts;
  {
    ::pliant::test::AllocationCounter counter;
    for (int f = 2; f < 12; ++f) step(f);
    counts = counter.stop();
  }
  std::size_t points = 0;
  for (int f = 2; f < 12; ++f) {
    ASSERT_GT(reports[static_cast<std::size_t>(f)].observed, 20);
    points += reports[static_cast<std::size_t>(f)].points;
  }
  EXPECT_EQ(counts.news, 0u) << "operator new calls";
  EXPECT_EQ(counts.deletes, 0u);
  EXPECT_EQ(counts.eigen_violations, 0u);
  if (::pliant::test::malloc_interposed()) {
    // nanoflann's node pool: at most points / 4 nodes of 32 bytes per tree (leaves hold 8 to 16
    // points), in 8 KiB blocks, re-malloced by every build.
    const std::size_t bound = points * 12 / 8192 + 2 * 10;
    EXPECT_GT(counts.mallocs, 0u);
    EXPECT_LE(counts.mallocs, bound) << "over " << points << " points in 10 frames";
    EXPECT_LE(counts.frees, counts.mallocs + bound);
  }
}

}  // namespace
}  // namespace pliant::vision
